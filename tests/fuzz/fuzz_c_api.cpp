// libFuzzer harness: the input is a sequence of C API calls (adaptors/c/insitu.h) on one
// instrument: create (a tiny valid configuration with fuzzed values, or fuzzed JSON text),
// set_field / set_field_strided with fuzzed type, dims, ghosts, strides, origin and spacing over
// a fixed 16^3 buffer whose bytes the input may also set, execute with a fuzzed step and time,
// finalize and destroy. Every status code is fine; a crash or sanitizer report is a finding.
// Only the memory the buffer holds is ever described: reading past it would be the caller's
// fault, not the library's.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include "fuzz_archive.hpp"
#include "insitu.h"

namespace {

constexpr std::int64_t kSide = 16;
constexpr std::int64_t kSamples = kSide * kSide * kSide;

const std::filesystem::path& directory() {
    static const std::filesystem::path path = insitu_fuzz::process_directory("insitu_fuzz_c_api");
    return path;
}

std::string fuzzed_config(FuzzedDataProvider& input, const std::filesystem::path& archive) {
    if (input.ConsumeBool()) {
        return input.ConsumeRandomLengthString(96);
    }
    const int every = input.ConsumeIntegralInRange(-1, 3);
    const int intervals = input.ConsumeIntegralInRange(-1, 5);
    const int width = input.ConsumeIntegralInRange(-1, 8);
    const int height = input.ConsumeIntegralInRange(-1, 8);
    const char* field = input.ConsumeBool() ? "v" : "";
    const char* mode = input.ConsumeBool() ? "uniform" : "adaptive";
    return std::string(R"({"fields": [")") + field + R"("], "views": [{"azimuth": )" +
           std::to_string(input.ConsumeIntegralInRange(-400, 400)) + R"(, "elevation": )" +
           std::to_string(input.ConsumeIntegralInRange(-100, 100)) + R"(, "size": [)" +
           std::to_string(width) + ", " + std::to_string(height) +
           R"(]}], "intervals": {"count": )" + std::to_string(intervals) + R"(, "mode": ")" + mode +
           R"("}, "every": )" + std::to_string(every) + R"(, "archive": ")" + archive.string() +
           R"("})";
}

// Fuzzed dims (with ghosts and strides) describing at most kSamples samples of the buffer.
struct Layout {
    std::array<std::int64_t, 3> dims{};
    std::array<std::int64_t, 3> ghosts{};
    std::array<std::int64_t, 3> strides{};
    std::array<double, 3> origin{};
    std::array<double, 3> spacing{};
    bool with_ghosts = false;
    bool with_strides = false;
    bool with_origin = false;
    bool with_spacing = false;
};

Layout fuzzed_layout(FuzzedDataProvider& input) {
    Layout layout;
    for (int axis = 0; axis < 3; ++axis) {
        layout.dims[axis] = input.ConsumeIntegralInRange<std::int64_t>(-1, kSide);
        layout.ghosts[axis] = input.ConsumeIntegralInRange<std::int64_t>(-1, 9);
        layout.strides[axis] = input.ConsumeIntegralInRange<std::int64_t>(-1, 2 * kSide * kSide);
        layout.origin[axis] = input.ConsumeFloatingPoint<double>();
        layout.spacing[axis] = input.ConsumeFloatingPoint<double>();
    }
    layout.with_ghosts = input.ConsumeBool();
    layout.with_strides = input.ConsumeBool();
    layout.with_origin = input.ConsumeBool();
    layout.with_spacing = input.ConsumeBool();
    if (layout.with_strides) {
        // The last sample's offset must lie inside the buffer (else the strides are dropped).
        std::int64_t last = 0;
        for (int axis = 0; axis < 3; ++axis) {
            if (layout.dims[axis] > 0 && layout.strides[axis] > 0) {
                last += (layout.dims[axis] - 1) * layout.strides[axis];
            }
        }
        layout.with_strides = last < kSamples;
    }
    return layout;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // Eight bytes a sample, so any scalar type's view of kSamples samples stays inside.
    static std::array<double, kSamples> buffer;
    for (std::int64_t i = 0; i < kSamples; ++i) {
        buffer[i] = static_cast<double>(i % 17) / 16.0;
    }
    FuzzedDataProvider input(data, size);
    const auto archive = directory() / "run.cdb";
    insitu_instrument* instrument = nullptr;
    for (int call = 0; call < 12 && input.remaining_bytes() > 0; ++call) {
        switch (input.ConsumeIntegralInRange(0, 5)) {
            case 0: {
                insitu_destroy(instrument);
                instrument = nullptr;
                std::filesystem::remove_all(archive);
                (void)insitu_create_from_json(fuzzed_config(input, archive).c_str(), &instrument);
                break;
            }
            case 1: {
                const std::string name =
                    input.ConsumeBool() ? "v" : input.ConsumeRandomLengthString(4);
                const int type = input.ConsumeIntegralInRange(-1, 5);
                const Layout layout = fuzzed_layout(input);
                const void* samples = input.ConsumeBool() ? buffer.data() : nullptr;
                (void)insitu_set_field_strided(
                    instrument, name.c_str(), samples, type, layout.dims.data(),
                    layout.with_origin ? layout.origin.data() : nullptr,
                    layout.with_spacing ? layout.spacing.data() : nullptr,
                    layout.with_ghosts ? layout.ghosts.data() : nullptr,
                    layout.with_strides ? layout.strides.data() : nullptr);
                break;
            }
            case 2: {
                const auto bytes = input.ConsumeBytes<std::uint8_t>(64);
                const std::size_t offset =
                    input.ConsumeIntegralInRange<std::size_t>(0, sizeof(buffer) - 64);
                if (!bytes.empty()) {
                    std::memcpy(reinterpret_cast<std::uint8_t*>(buffer.data()) + offset,
                                bytes.data(), bytes.size());
                }
                break;
            }
            case 3: {
                const std::int64_t step = input.ConsumeBool()
                                              ? input.ConsumeIntegralInRange<std::int64_t>(-1, 8)
                                              : input.ConsumeIntegral<std::int64_t>();
                (void)insitu_execute(instrument, step, input.ConsumeFloatingPoint<double>());
                break;
            }
            case 4:
                (void)insitu_finalize(instrument);
                break;
            default:
                insitu_destroy(instrument);
                instrument = nullptr;
                break;
        }
        (void)insitu_status_name(input.ConsumeIntegral<int>());
        (void)std::strlen(insitu_last_error());
    }
    insitu_destroy(instrument);
    return 0;
}
