// ComputeDevice: device selection, embedded kernel families and the errors that name what went
// wrong (kernel, family, selector).
#include "insitu/device/compute_device.hpp"

#include "device/opencl_device.hpp"

#include <algorithm>
#include <cctype>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/expect_error.hpp"

#include "insitu/error.hpp"

namespace insitu {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;

template <typename Function>
void expect_compute_error_naming(Function&& function, const std::string& expected_text) {
    insitu::testing::expect_error_naming<ComputeError>(function, expected_text);
}

TEST(ComputeDevice, SharedDeviceExistsAndDescribesItself) {
    const std::shared_ptr<ComputeDevice> device = ComputeDevice::shared();
    ASSERT_NE(device, nullptr);
    // "platform name / device name"
    EXPECT_THAT(device->description(), HasSubstr(" / "));
    EXPECT_GT(device->description().size(), 4u);
    // The same object every time.
    EXPECT_EQ(ComputeDevice::shared().get(), device.get());
}

TEST(ComputeDevice, EmbeddedFamiliesIncludeTheGroundTruthAndCommonHelpers) {
    const std::vector<std::string> families = ComputeDevice::embedded_families();
    EXPECT_THAT(families, Contains("volume_renderer"));
    EXPECT_THAT(families, Contains("common"));
}

TEST(ComputeDevice, BuildsAndFindsTheVolumeRenderKernel) {
    const cl::Kernel kernel = ComputeDevice::shared()->opencl().kernel("volume_renderer", "render_volume");
    EXPECT_EQ(kernel.getInfo<CL_KERNEL_FUNCTION_NAME>(), "render_volume");
}

TEST(ComputeDevice, UnknownKernelIsAComputeErrorNamingIt) {
    expect_compute_error_naming(
        [] { ComputeDevice::shared()->opencl().kernel("volume_renderer", "no_such_kernel"); },
        "no_such_kernel");
    expect_compute_error_naming(
        [] { ComputeDevice::shared()->opencl().kernel("volume_renderer", "no_such_kernel"); },
        "volume_renderer");
}

TEST(ComputeDevice, UnknownFamilyIsAComputeErrorNamingIt) {
    expect_compute_error_naming([] { ComputeDevice::shared()->opencl().kernel("no_such_family", "x"); },
                                "no_such_family");
}

TEST(ComputeDevice, SelectorThatMatchesNothingIsAComputeErrorNamingIt) {
    expect_compute_error_naming([] { ComputeDevice device("no-such-device-xyz"); },
                                "no-such-device-xyz");
    expect_compute_error_naming([] { ComputeDevice device("97:3"); }, "97:3");
}

TEST(ComputeDevice, SelectorMatchesAnyCaseOfTheDescription) {
    const ComputeDevice by_default("");
    std::string upper_case = by_default.description();
    std::transform(upper_case.begin(), upper_case.end(), upper_case.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    const ComputeDevice by_name(upper_case);
    EXPECT_EQ(by_name.description(), by_default.description());
}

TEST(ComputeDevice, BuffersGrowOnlyWhenTheyMust) {
    ComputeDevice& device = *ComputeDevice::shared();
    cl::Buffer buffer;
    std::size_t capacity = 0;
    device.opencl().ensure_buffer(buffer, capacity, 1024, CL_MEM_READ_WRITE);
    EXPECT_EQ(capacity, 1024u);
    cl_mem first = buffer();
    device.opencl().ensure_buffer(buffer, capacity, 512, CL_MEM_READ_WRITE);
    EXPECT_EQ(capacity, 1024u);
    EXPECT_EQ(buffer(), first);
    device.opencl().ensure_buffer(buffer, capacity, 4096, CL_MEM_READ_WRITE);
    EXPECT_EQ(capacity, 4096u);

    // Round trip through the device.
    std::vector<float> host(1024);
    for (std::size_t i = 0; i < host.size(); ++i) host[i] = 0.5f * static_cast<float>(i);
    device.opencl().upload(buffer, host.data(), host.size() * sizeof(float), "test data");
    std::vector<float> back(host.size(), -1.0f);
    device.opencl().download(buffer, back.data(), back.size() * sizeof(float), "test data");
    EXPECT_EQ(back, host);
}

TEST(ComputeDevice, StatusNamesAreReadable) {
    EXPECT_THAT(detail::opencl_status_name(CL_OUT_OF_RESOURCES), HasSubstr("CL_OUT_OF_RESOURCES"));
    EXPECT_THAT(detail::opencl_status_name(CL_OUT_OF_RESOURCES), HasSubstr("-5"));
    EXPECT_THAT(detail::opencl_status_name(-9999), HasSubstr("-9999"));
}

}  // namespace
}  // namespace insitu
