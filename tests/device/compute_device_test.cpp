// ComputeDevice: device selection, embedded kernel families and the errors that name what went
// wrong (kernel, family, selector).
#include "insitu/device/compute_device.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "device/opencl_device.hpp"
#include "insitu/error.hpp"
#include "support/expect_error.hpp"

namespace insitu {
namespace {

using ::testing::Contains;
using ::testing::ContainsRegex;
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

// Processes that share a node each take an equal part of a CPU device (at least one compute
// unit); the part runs a kernel as the whole device does. INSITU_DEVICE_SHARE=off (the MPI tests
// compare whole archives: tests/mpi/CMakeLists.txt, mpi_device_share) keeps the whole device.
TEST(ComputeDevice, AProcessOfTwoOnANodeTakesHalfACpuDevice) {
    ComputeDevice whole("");
    if (!whole.opencl().is_cpu()) GTEST_SKIP() << "GPUs are never split: " << whole.description();
    ComputeDevice half("", NodeShare{1, 2});
    const unsigned units = whole.compute_units();
    EXPECT_EQ(half.compute_units(), units >= 2 ? units / 2 : units) << half.description();
    if (units >= 2) {
        EXPECT_THAT(half.description(), HasSubstr("compute units, part 1"));
    }
    EXPECT_EQ(ComputeDevice("", NodeShare{0, 1}).compute_units(), units);
    ::setenv("INSITU_DEVICE_SHARE", "off", 1);
    EXPECT_EQ(ComputeDevice("", NodeShare{1, 2}).compute_units(), units);
    ::setenv("INSITU_DEVICE_SHARE", "sometimes", 1);
    insitu::testing::expect_error_naming<InvalidArgument>(
        [] {
            ComputeDevice("", NodeShare{1, 2});
        },
        "INSITU_DEVICE_SHARE = \"sometimes\"");
    ::unsetenv("INSITU_DEVICE_SHARE");
}

TEST(ComputeDevice, EmbeddedFamiliesIncludeTheGroundTruthAndCommonHelpers) {
    const std::vector<std::string> families = ComputeDevice::embedded_families();
    EXPECT_THAT(families, Contains("volume_renderer"));
    EXPECT_THAT(families, Contains("common"));
}

TEST(ComputeDevice, BuildsAndFindsTheVolumeRenderKernel) {
    const cl::Kernel kernel =
        ComputeDevice::shared()->opencl().kernel("volume_renderer", "render_volume");
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
    expect_compute_error_naming(
        [] { ComputeDevice::shared()->opencl().kernel("no_such_family", "x"); }, "no_such_family");
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

// A kernel that writes back its scalar and vector arguments, built through the same path as
// the embedded families.
cl::Kernel echo_arguments_kernel() {
    static const detail::EmbeddedKernel echo{
        "tests/device/echo_arguments.cl",
        "__kernel void echo_arguments(int a, int2 b, float4 c, __global float* out) {\n"
        "    out[0] = (float)a;\n"
        "    vstore2(convert_float2(b), 0, out + 1);\n"
        "    vstore4(c, 0, out + 3);\n"
        "}\n"};
    cl::Program program = ComputeDevice::shared()->opencl().build_program({&echo});
    return cl::Kernel(program, "echo_arguments");
}

TEST(ComputeDevice, PacksExpandIntoConsecutiveArgumentsInOrder) {
    detail::OpenClDevice& opencl = ComputeDevice::shared()->opencl();
    cl::Kernel kernel = echo_arguments_kernel();
    cl::Buffer out;
    std::size_t capacity = 0;
    opencl.ensure_buffer(out, capacity, 7 * sizeof(float), CL_MEM_WRITE_ONLY);
    // Nested packs flatten: (1, ((2, 3), (4, 5, 6, 7))) sets arguments a, b and c.
    const cl_int2 b = {{2, 3}};
    const cl_float4 c = {{4.0f, 5.0f, 6.0f, 7.0f}};
    opencl.launch(kernel, cl::NDRange(1), cl::NullRange,
                  detail::pack_args(cl_int{1}, detail::pack_args(b, c)), out);
    std::vector<float> values(7, -1.0f);
    opencl.download(out, values.data(), values.size() * sizeof(float), "echoed arguments");
    EXPECT_EQ(values, (std::vector<float>{1, 2, 3, 4, 5, 6, 7}));
}

TEST(ComputeDevice, LaunchWithTheWrongArgumentCountNamesTheKernelAndBothCounts) {
    detail::OpenClDevice& opencl = ComputeDevice::shared()->opencl();
    cl::Kernel kernel = echo_arguments_kernel();
    cl::Buffer out;
    std::size_t capacity = 0;
    opencl.ensure_buffer(out, capacity, 7 * sizeof(float), CL_MEM_WRITE_ONLY);
    const cl_int2 b = {{2, 3}};
    const cl_float4 c = {{4.0f, 5.0f, 6.0f, 7.0f}};
    auto launch_expecting = [&](auto&& launch, const std::string& given) {
        try {
            launch();
            ADD_FAILURE() << "no ComputeError for a launch that gave " << given << " arguments";
        } catch (const ComputeError& error) {
            EXPECT_THAT(error.what(), HasSubstr("\"echo_arguments\""));
            EXPECT_THAT(error.what(), HasSubstr("takes 4 arguments"));
            EXPECT_THAT(error.what(), HasSubstr("the launch gave " + given));
        }
    };
    launch_expecting([&] { opencl.launch(kernel, cl::NDRange(1), cl::NullRange, cl_int{1}, out); },
                     "2");
    // A pack counts as the arguments it expands into, not as one.
    launch_expecting(
        [&] {
            opencl.launch(kernel, cl::NDRange(1), cl::NullRange,
                          detail::pack_args(cl_int{1}, b, c, cl_int{0}), out);
        },
        "5");
    launch_expecting(
        [&] { opencl.launch(kernel, cl::NDRange(1), cl::NullRange, detail::pack_args(b, c), out); },
        "3");
}

TEST(ComputeDevice, FamiliesAreBuiltFromCommonTheirSharedFilesAndTheirOwn) {
    auto paths_of = [](const std::string& family) {
        std::vector<std::string> paths;
        for (const auto* part : detail::OpenClDevice::family_sources(family)) {
            paths.push_back(part->path);
        }
        return paths;
    };
    using Paths = std::vector<std::string>;
    // The ground truth and the proxies march with one skeleton (seed 000: the same samples).
    EXPECT_EQ(paths_of("volume_renderer"),
              (Paths{"kernels/device/common.cl", "kernels/render/ray_march.cl",
                     "kernels/render/volume_renderer.cl"}));
    EXPECT_EQ(paths_of("proxy_renderer"),
              (Paths{"kernels/device/common.cl", "kernels/render/ray_march.cl",
                     "kernels/render/proxy_renderer.cl"}));
    EXPECT_EQ(paths_of("relighting"),
              (Paths{"kernels/device/common.cl", "kernels/explore/relighting.cl"}));
    EXPECT_EQ(paths_of("common"), (Paths{"kernels/device/common.cl"}));
    expect_compute_error_naming([] { detail::OpenClDevice::family_sources("no_such_family"); },
                                "no_such_family");

    // Each part starts at line 1 of its own file.
    const auto parts = detail::OpenClDevice::family_sources("proxy_renderer");
    const std::string text = detail::OpenClDevice::compose_source(parts);
    for (const auto* part : parts) {
        EXPECT_NE(text.find("#line 1 \"" + part->path + "\"\n" + part->source), std::string::npos)
            << part->path;
    }
}

TEST(ComputeDevice, BuildErrorsNameTheFileAndLineOfThePartThatFailed) {
    // The broken part follows common.cl, so its line 3 is only reported as line 3 of its own
    // file if the #line directives work.
    const detail::EmbeddedKernel broken{"tests/device/broken_kernel.cl",
                                        "// A deliberate build error on line 3.\n"
                                        "__kernel void broken(__global float* out) {\n"
                                        "    out[0] = no_such_value;\n"
                                        "}\n"};
    const auto* common = detail::OpenClDevice::family_sources("common").front();
    try {
        ComputeDevice::shared()->opencl().build_program({common, &broken});
        ADD_FAILURE() << "a broken kernel built";
    } catch (const ComputeError& error) {
        EXPECT_THAT(error.what(), HasSubstr("building tests/device/broken_kernel.cl"));
        EXPECT_THAT(error.what(), HasSubstr("no_such_value"));
        // Compilers write "file:line:column" (clang, PoCL) or "file(line)".
        EXPECT_THAT(error.what(), ContainsRegex("broken_kernel\\.cl[:(]3[:)]"));
    }
}

TEST(ComputeDevice, StatusNamesAreReadable) {
    EXPECT_THAT(detail::opencl_status_name(CL_OUT_OF_RESOURCES), HasSubstr("CL_OUT_OF_RESOURCES"));
    EXPECT_THAT(detail::opencl_status_name(CL_OUT_OF_RESOURCES), HasSubstr("-5"));
    EXPECT_THAT(detail::opencl_status_name(-9999), HasSubstr("-9999"));
}

}  // namespace
}  // namespace insitu
