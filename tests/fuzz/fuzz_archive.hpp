#pragma once
// What the archive harnesses share: a folder of their own per process and a small real archive
// in it, written once through the C API (one 8x8 view, one step of a ball field), so that a
// fuzzed manifest or EXR file sits among files the reader can actually find.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "insitu.h"

namespace insitu_fuzz {

inline std::filesystem::path process_directory(const std::string& harness) {
    const auto directory =
        std::filesystem::temp_directory_path() / (harness + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(directory);
    std::filesystem::create_directories(directory);
    // Removed at exit (libFuzzer ends a run with exit()), so runs leave no folders behind.
    static const struct Remover {
        std::filesystem::path path;
        ~Remover() {
            std::error_code ignored;
            std::filesystem::remove_all(path, ignored);
        }
    } remover{directory};
    return directory;
}

inline std::string tiny_config(const std::filesystem::path& archive) {
    return R"({"fields": ["v"], "views": [{"azimuth": 30, "elevation": 20, "size": [8, 8]}],
               "intervals": {"count": 2, "mode": "uniform"}, "every": 1, "archive": ")" +
           archive.string() + R"("})";
}

// Writes step 0 of a 16^3 ball into `archive`; aborts (a harness set-up failure, not a finding)
// when the library refuses.
inline void write_tiny_archive(const std::filesystem::path& archive) {
    constexpr std::int64_t n = 16;
    std::vector<float> samples(n * n * n);
    const double center = 0.5 * (n - 1);
    for (std::int64_t k = 0; k < n; ++k) {
        for (std::int64_t j = 0; j < n; ++j) {
            for (std::int64_t i = 0; i < n; ++i) {
                const double r =
                    std::sqrt((i - center) * (i - center) + (j - center) * (j - center) +
                              (k - center) * (k - center));
                samples[i + n * (j + n * k)] = static_cast<float>(std::fmax(0.0, 1.0 - r / center));
            }
        }
    }
    const std::int64_t dims[3] = {n, n, n};
    insitu_instrument* instrument = nullptr;
    if (insitu_create_from_json(tiny_config(archive).c_str(), &instrument) != INSITU_OK ||
        insitu_set_field(instrument, "v", samples.data(), INSITU_FLOAT32, dims, nullptr, nullptr,
                         nullptr) != INSITU_OK ||
        insitu_execute(instrument, 0, 0.0) != INSITU_OK ||
        insitu_finalize(instrument) != INSITU_OK) {
        std::fprintf(stderr, "fuzz set-up: %s\n", insitu_last_error());
        std::abort();
    }
    insitu_destroy(instrument);
}

}  // namespace insitu_fuzz
