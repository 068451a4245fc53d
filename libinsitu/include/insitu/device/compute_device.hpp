#pragma once
// ComputeDevice: the one owner of the OpenCL platform, context, queue and programs.
//
// Device choice: PoCL's CPU device by default (it is on every machine scripts/setup prepares);
// the environment variable INSITU_OPENCL_DEVICE picks another:
//   "P:D"        platform index P, device index D (as clinfo -l lists them)
//   "text"       first device whose "platform name / device name" contains text (case-insensitive)
// Kernel sources come from kernels/**/*.cl, embedded at build time; each family (file) is built
// at most once per process, on first use. Every error names the kernel and carries the build log.
//
// This header carries no OpenCL type or macro, so a simulation that includes it does not see
// the OpenCL headers: the OpenCL objects live in detail::OpenClDevice
// (libinsitu/src/device/opencl_device.hpp), which only the library's own code includes.
#include <memory>
#include <string>
#include <vector>

namespace insitu {

namespace detail {
class OpenClDevice;
}

class ComputeDevice {
public:
    /// The process-wide device, created on first call (thread-safe). Throws ComputeError with a
    /// clear message when no OpenCL platform exists or INSITU_OPENCL_DEVICE matches nothing.
    static std::shared_ptr<ComputeDevice> shared();

    /// Creates a device from an explicit selector (same syntax as INSITU_OPENCL_DEVICE;
    /// empty = default choice). Mostly for tests and tools.
    explicit ComputeDevice(const std::string& selector);
    ~ComputeDevice();

    ComputeDevice(const ComputeDevice&) = delete;
    ComputeDevice& operator=(const ComputeDevice&) = delete;

    /// "platform name / device name".
    const std::string& description() const;

    /// Names of the embedded kernel families (file stems of kernels/**/*.cl).
    static std::vector<std::string> embedded_families();

    /// The OpenCL objects, for the library's own renderers and exploration kernels.
    detail::OpenClDevice& opencl() { return *opencl_; }

private:
    std::unique_ptr<detail::OpenClDevice> opencl_;
};

}  // namespace insitu
