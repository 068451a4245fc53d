#pragma once
// The OpenCL side of ComputeDevice (insitu/device/compute_device.hpp): platform, context, queue,
// the embedded programs and the one launcher every kernel goes through. Private to the library:
// public headers never include OpenCL.
#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include "insitu/device/compute_device.hpp"
#include "insitu/error.hpp"

namespace insitu::detail {

/// One kernel file: its path in the source tree (for #line and messages) and its text.
struct EmbeddedKernel {
    std::string path;
    std::string source;
};

/// Consecutive kernel arguments that belong to one concept (a camera, a volume, a transfer
/// table), made by the packers of device/kernel_args.hpp; packs may nest. OpenClDevice::launch
/// sets each element as its own kernel argument, in order, and counts each one.
template <typename... Values>
struct ArgumentPack {
    std::tuple<Values...> values;
};

template <typename... Values>
ArgumentPack<Values...> pack_args(Values... values) {
    return {std::tuple<Values...>(std::move(values)...)};
}

/// How many kernel arguments a launch argument stands for: 1, or a pack's expanded count.
template <typename T>
struct ArgumentCount {
    static constexpr std::size_t value = 1;
};
template <typename... Values>
struct ArgumentCount<ArgumentPack<Values...>> {
    static constexpr std::size_t value = (std::size_t{0} + ... + ArgumentCount<Values>::value);
};

class OpenClDevice {
public:
    /// The device `selector` picks, or this process's part of it where `share` says the node is
    /// shared (device/device_share.hpp).
    explicit OpenClDevice(const std::string& selector, const NodeShare& share = {});

    /// "platform name / device name".
    const std::string& description() const { return description_; }
    cl::Context& context() { return context_; }
    cl::CommandQueue& queue() { return queue_; }
    const cl::Device& device() const { return device_; }
    /// Whether the device is a CPU (PoCL's pthread device, the default). Ray packets pay there,
    /// where a work-group's work-items run one after another; a GPU runs work-items in SIMD lanes
    /// of its own, and 16 rays per work-item would only cut its parallelism.
    bool is_cpu() const { return is_cpu_; }
    /// The compute units of the device taken (a part's where the node is shared).
    unsigned compute_units() const { return compute_units_; }

    /// A kernel from the embedded source of `family` (kernels/<stage>/<family>.cl), building that
    /// family on first use with the shared constants of device/kernel_constants.hpp as -D options.
    cl::Kernel kernel(const std::string& family, const std::string& kernel_name);

    /// The files `family` is built from, in order: kernels/device/common.cl (every family), the
    /// shared files the family lists (kernels/render/ray_march.cl for the ground truth and the
    /// proxies, which must take the same samples), then the family's own file. ComputeError for
    /// an unknown family.
    static std::vector<const EmbeddedKernel*> family_sources(const std::string& family);

    /// `parts` as one program source, each preceded by `#line 1 "<its path>"`, so compiler
    /// messages name the file and line of the part they are about.
    static std::string compose_source(const std::vector<const EmbeddedKernel*>& parts);

    /// Builds compose_source(parts) with build_options(); ComputeError naming the last part (the
    /// family's own file) and carrying the build log when it fails.
    cl::Program build_program(const std::vector<const EmbeddedKernel*>& parts);

    /// The -D options every family is built with (one per host constant the kernels share).
    static std::string build_options();

    /// Sets the arguments and enqueues `kernel` over `global` work-items (local size chosen by the
    /// implementation unless given). An ArgumentPack sets its elements as consecutive arguments.
    /// The number of arguments, packs expanded, must be the kernel's own count (ComputeError
    /// naming the kernel and both counts otherwise), so a launch that forgot or added an
    /// argument fails at once instead of reading garbage. In debug builds (or with
    /// INSITU_OPENCL_SYNC=1) waits for the kernel and checks its status, so an error points at
    /// the launch that caused it.
    template <typename... Args>
    void launch(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local,
                const Args&... args) {
        std::lock_guard<std::mutex> lock(launch_mutex_);
        check_argument_count(kernel, (std::size_t{0} + ... + ArgumentCount<Args>::value));
        cl_uint index = 0;
        try {
            (set_argument(kernel, index, args), ...);
        } catch (const cl::Error& error) {
            fail_launch(kernel, "setting argument " + std::to_string(index), error);
        }
        enqueue(kernel, global, local);
    }

    /// A device buffer of at least `bytes`, reallocated only when it must grow, so uploads of
    /// successive timesteps reuse memory.
    void ensure_buffer(cl::Buffer& buffer, std::size_t& capacity_bytes, std::size_t bytes,
                       cl_mem_flags flags);

    /// Blocking copies that turn OpenCL failures into ComputeError naming `what`; an upload
    /// writes `bytes` at `offset` bytes into the buffer.
    void upload(cl::Buffer& buffer, const void* host, std::size_t bytes, const char* what,
                std::size_t offset = 0);
    void download(const cl::Buffer& buffer, void* host, std::size_t bytes, const char* what);

private:
    template <typename T>
    static void set_argument(cl::Kernel& kernel, cl_uint& index, const T& value) {
        kernel.setArg(index, value);
        ++index;
    }
    template <typename... Values>
    static void set_argument(cl::Kernel& kernel, cl_uint& index,
                             const ArgumentPack<Values...>& pack) {
        std::apply([&](const auto&... values) { (set_argument(kernel, index, values), ...); },
                   pack.values);
    }

    void check_argument_count(cl::Kernel& kernel, std::size_t given);
    void enqueue(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local);
    [[noreturn]] void fail_launch(cl::Kernel& kernel, const std::string& stage,
                                  const cl::Error& error);
    cl::Program& program(const std::string& family);

    cl::Platform platform_;
    cl::Device device_;
    cl::Context context_;
    cl::CommandQueue queue_;
    std::string description_;
    bool is_cpu_ = false;  ///< asked once: every pass consults it
    unsigned compute_units_ = 0;
    bool synchronous_launches_ = false;
    std::mutex program_mutex_;
    std::mutex launch_mutex_;
    std::map<std::string, cl::Program> programs_;
};

/// A device buffer reused while it does not grow (OpenClDevice::ensure_buffer).
struct DeviceMemory {
    cl::Buffer buffer;
    std::size_t capacity = 0;
};

/// Text for an OpenCL status code, e.g. "CL_OUT_OF_RESOURCES (-5)".
std::string opencl_status_name(cl_int status);

/// Every kernels/**/*.cl file keyed by its stem (generated by cmake/embed_kernels.cmake).
const std::map<std::string, EmbeddedKernel>& embedded_kernel_sources();

}  // namespace insitu::detail
