#pragma once
// ComputeDevice: the one owner of the OpenCL platform, context, queue and programs.
//
// Device choice: PoCL's CPU device by default (it is on every machine scripts/setup prepares);
// the environment variable INSITU_OPENCL_DEVICE picks another:
//   "P:D"        platform index P, device index D (as clinfo -l lists them)
//   "text"       first device whose "platform name / device name" contains text (case-insensitive)
// Kernel sources come from kernels/*.cl, embedded at build time; each family (file) is built at
// most once per process, on first use. Every error names the kernel and carries the build log.
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include "insitu/error.hpp"

namespace insitu {

class ComputeDevice {
public:
    /// The process-wide device, created on first call (thread-safe). Throws ComputeError with a
    /// clear message when no OpenCL platform exists or INSITU_OPENCL_DEVICE matches nothing.
    static std::shared_ptr<ComputeDevice> shared();

    /// Creates a device from an explicit selector (same syntax as INSITU_OPENCL_DEVICE;
    /// empty = default choice). Mostly for tests and tools.
    explicit ComputeDevice(const std::string& selector);

    ComputeDevice(const ComputeDevice&) = delete;
    ComputeDevice& operator=(const ComputeDevice&) = delete;

    /// "platform name / device name".
    const std::string& description() const { return description_; }
    cl::Context& context() { return context_; }
    cl::CommandQueue& queue() { return queue_; }
    const cl::Device& device() const { return device_; }

    /// A kernel from the embedded source `kernels/<family>.cl`, building that family on first use.
    cl::Kernel kernel(const std::string& family, const std::string& kernel_name);

    /// Sets the arguments and enqueues `kernel` over `global` work-items (local size chosen by the
    /// implementation unless given). In debug builds (or with INSITU_OPENCL_SYNC=1) waits for the
    /// kernel and checks its status, so an error points at the launch that caused it.
    template <typename... Args>
    void launch(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local,
                const Args&... args) {
        std::lock_guard<std::mutex> lock(launch_mutex_);
        cl_uint index = 0;
        try {
            (kernel.setArg(index++, args), ...);
        } catch (const cl::Error& error) {
            fail_launch(kernel, "setting argument " + std::to_string(index - 1), error);
        }
        enqueue(kernel, global, local);
    }

    /// A device buffer of at least `bytes`, reallocated only when it must grow, so uploads of
    /// successive timesteps reuse memory.
    void ensure_buffer(cl::Buffer& buffer, std::size_t& capacity_bytes, std::size_t bytes,
                       cl_mem_flags flags);

    /// Blocking copies that turn OpenCL failures into ComputeError naming `what`.
    void upload(cl::Buffer& buffer, const void* host, std::size_t bytes, const char* what);
    void download(const cl::Buffer& buffer, void* host, std::size_t bytes, const char* what);

    /// Names of the embedded kernel families (file stems of kernels/*.cl).
    static std::vector<std::string> embedded_families();

private:
    void enqueue(cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local);
    [[noreturn]] void fail_launch(cl::Kernel& kernel, const std::string& stage,
                                  const cl::Error& error);
    cl::Program& program(const std::string& family);

    cl::Platform platform_;
    cl::Device device_;
    cl::Context context_;
    cl::CommandQueue queue_;
    std::string description_;
    bool synchronous_launches_ = false;
    std::mutex program_mutex_;
    std::mutex launch_mutex_;
    std::map<std::string, cl::Program> programs_;
};

/// Text for an OpenCL status code, e.g. "CL_OUT_OF_RESOURCES (-5)".
std::string opencl_status_name(cl_int status);

}  // namespace insitu
