#include "insitu/device/compute_device.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <sstream>

#include "device/device_share.hpp"
#include "device/kernel_constants.hpp"
#include "device/opencl_device.hpp"

namespace insitu {
namespace detail {

namespace {

std::string lower(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return text;
}

std::string describe(const cl::Platform& platform, const cl::Device& device) {
    return platform.getInfo<CL_PLATFORM_NAME>() + " / " + device.getInfo<CL_DEVICE_NAME>();
}

struct Choice {
    cl::Platform platform;
    cl::Device device;
};

// Lists "P:D platform / device" for error messages, so a user sees what can be chosen.
std::string list_devices(const std::vector<cl::Platform>& platforms) {
    std::ostringstream out;
    for (std::size_t p = 0; p < platforms.size(); ++p) {
        std::vector<cl::Device> devices;
        platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
        for (std::size_t d = 0; d < devices.size(); ++d) {
            out << (out.tellp() > 0 ? "; " : "") << p << ":" << d << " "
                << describe(platforms[p], devices[d]);
        }
    }
    return out.str();
}

Choice choose_device(const std::string& selector) {
    std::vector<cl::Platform> platforms;
    try {
        cl::Platform::get(&platforms);
    } catch (const cl::Error& error) {
        // The ICD loader reports "no platform" as an error code, not an empty list.
        platforms.clear();
    }
    if (platforms.empty()) {
        fail<ComputeError>(
            "no OpenCL platform found: install an OpenCL driver (scripts/setup "
            "installs PoCL, Debian package pocl-opencl-icd) or check "
            "/etc/OpenCL/vendors");
    }

    std::vector<Choice> all;
    for (const auto& platform : platforms) {
        std::vector<cl::Device> devices;
        try {
            platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
        } catch (const cl::Error&) {
            continue;  // a platform without devices is skipped, not fatal
        }
        for (const auto& device : devices) all.push_back({platform, device});
    }
    if (all.empty()) fail<ComputeError>("OpenCL platforms found but no devices on any of them");

    if (selector.empty()) {
        // Default: PoCL's CPU device, which the project is measured on; otherwise the first device.
        for (const auto& choice : all) {
            if (lower(choice.platform.getInfo<CL_PLATFORM_NAME>()).find("portable computing") !=
                    std::string::npos &&
                choice.device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) {
                return choice;
            }
        }
        return all.front();
    }

    const auto colon = selector.find(':');
    const bool numeric = std::all_of(selector.begin(), selector.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) || c == ':';
    });
    if (colon != std::string::npos && colon > 0 && numeric) {
        const std::size_t p = std::stoul(selector.substr(0, colon));
        const std::size_t d = std::stoul(selector.substr(colon + 1));
        if (p < platforms.size()) {
            std::vector<cl::Device> devices;
            platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
            if (d < devices.size()) return {platforms[p], devices[d]};
        }
    } else {
        for (const auto& choice : all) {
            if (lower(describe(choice.platform, choice.device)).find(lower(selector)) !=
                std::string::npos) {
                return choice;
            }
        }
    }
    fail<ComputeError>("INSITU_OPENCL_DEVICE = \"", selector,
                       "\" matches no OpenCL device (available: ", list_devices(platforms), ")");
}

}  // namespace

std::string opencl_status_name(cl_int status) {
    switch (status) {
#define INSITU_CL_CASE(code) \
    case code:               \
        return std::string(#code) + " (" + std::to_string(code) + ")";
        INSITU_CL_CASE(CL_SUCCESS)
        INSITU_CL_CASE(CL_DEVICE_NOT_FOUND)
        INSITU_CL_CASE(CL_OUT_OF_RESOURCES)
        INSITU_CL_CASE(CL_OUT_OF_HOST_MEMORY)
        INSITU_CL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
        INSITU_CL_CASE(CL_BUILD_PROGRAM_FAILURE)
        INSITU_CL_CASE(CL_INVALID_VALUE)
        INSITU_CL_CASE(CL_INVALID_BUFFER_SIZE)
        INSITU_CL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
        INSITU_CL_CASE(CL_INVALID_KERNEL_NAME)
        INSITU_CL_CASE(CL_INVALID_KERNEL_ARGS)
        INSITU_CL_CASE(CL_INVALID_ARG_INDEX)
        INSITU_CL_CASE(CL_INVALID_ARG_VALUE)
        INSITU_CL_CASE(CL_INVALID_ARG_SIZE)
        INSITU_CL_CASE(CL_INVALID_MEM_OBJECT)
        INSITU_CL_CASE(CL_INVALID_WORK_GROUP_SIZE)
        INSITU_CL_CASE(CL_INVALID_WORK_ITEM_SIZE)
        INSITU_CL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
        INSITU_CL_CASE(CL_PLATFORM_NOT_FOUND_KHR)
#undef INSITU_CL_CASE
        default:
            return "OpenCL status " + std::to_string(status);
    }
}

OpenClDevice::OpenClDevice(const std::string& selector, const NodeShare& share) {
    try {
        const Choice choice = choose_device(selector);
        platform_ = choice.platform;
        std::string note;
        device_ = take_share(choice.device, share, note);
        description_ = describe(platform_, device_) + (note.empty() ? "" : " (" + note + ")");
        is_cpu_ = (device_.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0;
        compute_units_ = device_.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
        context_ = cl::Context(device_);
        queue_ = cl::CommandQueue(context_, device_);
    } catch (const cl::Error& error) {
        fail<ComputeError>("OpenCL initialisation failed in ", error.what(), ": ",
                           opencl_status_name(error.err()));
    }
#ifndef NDEBUG
    synchronous_launches_ = true;
#endif
    if (const char* sync = std::getenv("INSITU_OPENCL_SYNC")) {
        synchronous_launches_ = std::string(sync) == "1";
    }
}

std::string OpenClDevice::build_options() {
    // Kernels are written for float accuracy that tests check against double references;
    // no fast-math flags so results do not depend on the compiler's mood.
    std::string options = "-cl-std=CL1.2";
    for (const KernelConstant& constant : kKernelConstants) {
        options += std::string(" -D") + constant.name + "=" + std::to_string(constant.value);
    }
    return options;
}

namespace {

// Shared kernel files a family needs after common.cl and before its own file, in order, by
// stem. The ground truth and the proxies march with one skeleton, so they take the same samples
// (seed 000; DESIGN.md "Proxies").
const std::map<std::string, std::vector<std::string>>& shared_files_of_families() {
    static const std::map<std::string, std::vector<std::string>> shared{
        {"volume_renderer", {"ray_march"}},
        {"proxy_renderer", {"ray_march"}},
    };
    return shared;
}

const EmbeddedKernel& embedded(const std::string& stem) {
    const auto& sources = embedded_kernel_sources();
    const auto found = sources.find(stem);
    if (found == sources.end()) {
        fail<ComputeError>("no embedded kernel family \"", stem, "\" (kernels/**/", stem, ".cl)");
    }
    return found->second;
}

}  // namespace

std::vector<const EmbeddedKernel*> OpenClDevice::family_sources(const std::string& family) {
    const EmbeddedKernel& own = embedded(family);
    std::vector<const EmbeddedKernel*> parts;
    if (family != "common") parts.push_back(&embedded("common"));
    const auto& shared = shared_files_of_families();
    const auto listed = shared.find(family);
    if (listed != shared.end()) {
        for (const std::string& stem : listed->second) parts.push_back(&embedded(stem));
    }
    parts.push_back(&own);
    return parts;
}

std::string OpenClDevice::compose_source(const std::vector<const EmbeddedKernel*>& parts) {
    std::string text;
    for (const EmbeddedKernel* part : parts) {
        text += "#line 1 \"" + part->path + "\"\n" + part->source + "\n";
    }
    return text;
}

cl::Program OpenClDevice::build_program(const std::vector<const EmbeddedKernel*>& parts) {
    const std::string& path = parts.back()->path;
    cl::Program program(context_, compose_source(parts));
    try {
        program.build({device_}, build_options().c_str());
    } catch (const cl::BuildError& error) {
        std::string log;
        for (const auto& entry : error.getBuildLog()) log += entry.second;
        fail<ComputeError>("building ", path, " for ", description_,
                           " failed: ", opencl_status_name(error.err()), "\nbuild log:\n", log);
    } catch (const cl::Error& error) {
        fail<ComputeError>("building ", path, " failed: ", opencl_status_name(error.err()));
    }
    return program;
}

cl::Program& OpenClDevice::program(const std::string& family) {
    std::lock_guard<std::mutex> lock(program_mutex_);
    auto found = programs_.find(family);
    if (found != programs_.end()) return found->second;
    cl::Program built = build_program(family_sources(family));
    return programs_.emplace(family, std::move(built)).first->second;
}

cl::Kernel OpenClDevice::kernel(const std::string& family, const std::string& kernel_name) {
    cl::Program& built = program(family);
    try {
        return cl::Kernel(built, kernel_name.c_str());
    } catch (const cl::Error& error) {
        fail<ComputeError>("kernel \"", kernel_name, "\" in ",
                           embedded_kernel_sources().at(family).path, ": ",
                           opencl_status_name(error.err()));
    }
}

void OpenClDevice::check_argument_count(cl::Kernel& kernel, std::size_t given) {
    cl_uint expected = 0;
    try {
        expected = kernel.getInfo<CL_KERNEL_NUM_ARGS>();
    } catch (const cl::Error& error) {
        fail_launch(kernel, "reading the argument count", error);
    }
    if (given != expected) {
        std::string name = "?";
        try {
            name = kernel.getInfo<CL_KERNEL_FUNCTION_NAME>();
        } catch (const cl::Error&) {
        }
        fail<ComputeError>("kernel \"", name, "\" takes ", expected, " arguments, the launch gave ",
                           given);
    }
}

void OpenClDevice::enqueue(cl::Kernel& kernel, const cl::NDRange& global,
                           const cl::NDRange& local) {
    try {
        cl::Event event;
        queue_.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &event);
        if (synchronous_launches_) {
            event.wait();
            const cl_int status = event.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>();
            if (status < 0) {
                fail_launch(kernel, "execution", cl::Error(status, "kernel execution"));
            }
        }
    } catch (const cl::Error& error) {
        fail_launch(kernel, "enqueue", error);
    }
}

void OpenClDevice::fail_launch(cl::Kernel& kernel, const std::string& stage,
                               const cl::Error& error) {
    std::string name = "?";
    try {
        name = kernel.getInfo<CL_KERNEL_FUNCTION_NAME>();
    } catch (const cl::Error&) {
    }
    fail<ComputeError>("kernel \"", name, "\" on ", description_, ": ", stage,
                       " failed: ", opencl_status_name(error.err()));
}

void OpenClDevice::ensure_buffer(cl::Buffer& buffer, std::size_t& capacity_bytes, std::size_t bytes,
                                 cl_mem_flags flags) {
    if (bytes == 0) bytes = 1;  // OpenCL forbids empty buffers
    if (capacity_bytes >= bytes && buffer()) return;
    try {
        buffer = cl::Buffer(context_, flags, bytes);
        capacity_bytes = bytes;
    } catch (const cl::Error& error) {
        fail<ComputeError>("allocating a device buffer of ", bytes, " bytes on ", description_,
                           " failed: ", opencl_status_name(error.err()));
    }
}

void OpenClDevice::upload(cl::Buffer& buffer, const void* host, std::size_t bytes, const char* what,
                          std::size_t offset) {
    try {
        queue_.enqueueWriteBuffer(buffer, CL_TRUE, offset, bytes, host);
    } catch (const cl::Error& error) {
        fail<ComputeError>("uploading ", what, " (", bytes,
                           " bytes): ", opencl_status_name(error.err()));
    }
}

void OpenClDevice::download(const cl::Buffer& buffer, void* host, std::size_t bytes,
                            const char* what) {
    try {
        queue_.enqueueReadBuffer(buffer, CL_TRUE, 0, bytes, host);
    } catch (const cl::Error& error) {
        fail<ComputeError>("downloading ", what, " (", bytes,
                           " bytes): ", opencl_status_name(error.err()));
    }
}

}  // namespace detail

namespace {

// The process-wide device and the node share it is made with, under one lock.
struct SharedDevice {
    std::mutex mutex;
    std::shared_ptr<ComputeDevice> instance;
    NodeShare share;
};

SharedDevice& shared_device() {
    static SharedDevice device;
    return device;
}

}  // namespace

std::shared_ptr<ComputeDevice> ComputeDevice::shared() {
    SharedDevice& device = shared_device();
    std::lock_guard<std::mutex> lock(device.mutex);
    if (!device.instance) {
        const char* selector = std::getenv("INSITU_OPENCL_DEVICE");
        device.instance = std::make_shared<ComputeDevice>(selector ? selector : "", device.share);
    }
    return device.instance;
}

bool ComputeDevice::share_node(NodeShare share) {
    SharedDevice& device = shared_device();
    std::lock_guard<std::mutex> lock(device.mutex);
    device.share = share;
    return !device.instance;
}

ComputeDevice::ComputeDevice(const std::string& selector, NodeShare share)
    : opencl_(std::make_unique<detail::OpenClDevice>(selector, share)) {}

unsigned ComputeDevice::compute_units() const {
    return opencl_->compute_units();
}

ComputeDevice::~ComputeDevice() = default;

const std::string& ComputeDevice::description() const {
    return opencl_->description();
}

std::vector<std::string> ComputeDevice::embedded_families() {
    std::vector<std::string> names;
    for (const auto& entry : detail::embedded_kernel_sources()) names.push_back(entry.first);
    return names;
}

}  // namespace insitu
