#include "render/gradient_volume.hpp"

#include "device/kernel_constants.hpp"
#include "insitu/error.hpp"

namespace insitu::detail {

GradientVolume::GradientVolume(OpenClDevice& opencl)
    : kernel_(opencl.kernel("gradient_volume", "gradient_volume")) {}

const cl::Buffer& GradientVolume::of(OpenClDevice& opencl, const DeviceVolume& volume) {
    if (volume.empty()) fail<Error>("GradientVolume::of called before upload()");
    if (built_generation_ == volume.generation) return memory_.buffer;
    opencl.ensure_buffer(memory_.buffer, memory_.capacity, bytes_for(volume), CL_MEM_READ_WRITE);
    const Index3& d = volume.dims;
    const cl_int4 dims = {
        {static_cast<cl_int>(d[0]), static_cast<cl_int>(d[1]), static_cast<cl_int>(d[2]), 0}};
    // One work-item per brick row of x (gradient_volume.cl).
    const auto bricks_x = static_cast<std::size_t>(volume_bricks(d[0]));
    opencl.launch(
        kernel_,
        cl::NDRange(bricks_x, static_cast<std::size_t>(d[1]), static_cast<std::size_t>(d[2])),
        cl::NullRange, volume.memory->buffer, dims, memory_.buffer);
    built_generation_ = volume.generation;
    return memory_.buffer;
}

}  // namespace insitu::detail
