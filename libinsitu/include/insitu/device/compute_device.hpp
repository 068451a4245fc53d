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
// Processes that share a node (the ranks of an MPI job: the MPI adaptor tells share_node when
// its communicator is made) each take an equal part of a CPU device's compute units, by OpenCL
// device fission, so that their device threads do not outnumber the cores; INSITU_DEVICE_SHARE
// = "off" keeps the whole device in every process ("auto", the default, shares). GPUs are never
// split. description() says which part a process took, or why it took the whole device.
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

/// Which of the processes that share this node's device this one is (index in [0, count)).
struct NodeShare {
    int index = 0;
    int count = 1;
};

class ComputeDevice {
public:
    /// Registers this process's share of the node for the process-wide device (shared()).
    /// Returns false where that device was already made (it then keeps what it took).
    static bool share_node(NodeShare share);

    /// The process-wide device, created on first call (thread-safe). Throws ComputeError with a
    /// clear message when no OpenCL platform exists or INSITU_OPENCL_DEVICE matches nothing.
    static std::shared_ptr<ComputeDevice> shared();

    /// Creates a device from an explicit selector (same syntax as INSITU_OPENCL_DEVICE;
    /// empty = default choice). Mostly for tests and tools.
    explicit ComputeDevice(const std::string& selector, NodeShare share = {});
    ~ComputeDevice();

    ComputeDevice(const ComputeDevice&) = delete;
    ComputeDevice& operator=(const ComputeDevice&) = delete;

    /// "platform name / device name", and "(part of it ...)" where the node is shared.
    const std::string& description() const;

    /// The compute units this process's device has: a part's where the node is shared.
    unsigned compute_units() const;

    /// Names of the embedded kernel families (file stems of kernels/**/*.cl).
    static std::vector<std::string> embedded_families();

    /// The OpenCL objects, for the library's own renderers and exploration kernels.
    detail::OpenClDevice& opencl() { return *opencl_; }

private:
    std::unique_ptr<detail::OpenClDevice> opencl_;
};

}  // namespace insitu
