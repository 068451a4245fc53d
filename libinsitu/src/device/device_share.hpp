#pragma once
// A process's share of a CPU device that several processes on one node use (the ranks of an MPI
// job): OpenCL device fission (clCreateSubDevices) into equal parts, one part a process, so that
// the ranks' device threads do not outnumber the node's cores (bench/RESULTS.md, "Compositing
// cost under MPI: one core's share per rank"). PoCL's pthread device runs a sub-device's kernels
// on as many of its worker threads as the sub-device has compute units.
#include <string>

#include "device/opencl_device.hpp"

namespace insitu::detail {

/// The device this process uses out of `whole`: a part of about 1/`share.count` of its compute
/// units (part `share.index` modulo the parts made), or `whole` itself where the device is no
/// CPU, one process runs on the node, INSITU_DEVICE_SHARE is "off", or the driver refuses the
/// partition. `note` says which, for the device's description.
cl::Device take_share(const cl::Device& whole, const NodeShare& share, std::string& note);

}  // namespace insitu::detail
