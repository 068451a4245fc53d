#include "device/device_share.hpp"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <vector>

namespace insitu::detail {

namespace {

// INSITU_DEVICE_SHARE: "off" keeps the whole device in every process; unset or "auto" shares.
bool sharing_wanted() {
    const char* value = std::getenv("INSITU_DEVICE_SHARE");
    if (value == nullptr) return true;
    const std::string text(value);
    if (text == "off") return false;
    if (text.empty() || text == "auto") return true;
    fail<InvalidArgument>("INSITU_DEVICE_SHARE = \"", text, "\": expected \"auto\" or \"off\"");
}

}  // namespace

cl::Device take_share(const cl::Device& whole, const NodeShare& share, std::string& note) {
    note.clear();
    if (share.count <= 1) return whole;
    if ((whole.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) == 0) return whole;  // GPU: whole
    if (!sharing_wanted()) {
        note = "whole device, INSITU_DEVICE_SHARE=off";
        return whole;
    }
    const cl_uint units = whole.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
    const cl_uint part = std::max<cl_uint>(1, units / static_cast<cl_uint>(share.count));
    if (part >= units) return whole;  // one unit: nothing to split
    const cl_device_partition_property properties[] = {
        CL_DEVICE_PARTITION_EQUALLY, static_cast<cl_device_partition_property>(part), 0};
    std::vector<cl::Device> parts;
    cl_int status = CL_SUCCESS;
    try {
        cl::Device device = whole;
        status = device.createSubDevices(properties, &parts);
    } catch (const cl::Error& error) {
        status = error.err();
    }
    if (status != CL_SUCCESS || parts.empty()) {
        note = "whole device: the driver refused a partition into parts of " +
               std::to_string(part) + " compute units (" + opencl_status_name(status) + ")";
        std::cerr << "insitu: note: " << share.count << " processes share this node's " << units
                  << " compute units; " << note
                  << ", so their device threads may outnumber the cores "
                     "(INSITU_DEVICE_SHARE=off keeps the whole device without this note)"
                  << std::endl;
        return whole;
    }
    const std::size_t mine = static_cast<std::size_t>(share.index) % parts.size();
    note = std::to_string(part) + " of " + std::to_string(units) + " compute units, part " +
           std::to_string(mine) + ": " + std::to_string(share.count) + " processes on this node";
    return parts[mine];
}

}  // namespace insitu::detail
