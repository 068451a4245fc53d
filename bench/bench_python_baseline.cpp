// The C++ side of bench/bench_python.py: the same Instrument::execute on the same float64 field
// that the benchmark hands over from Python, timed and measured the same way (wall time per
// call, peak resident memory gained over the call), printed as one JSON line. Never a test.
//
//   bench_python_baseline --size N --image P --repeats R --archive DIR
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "insitu/instrument.hpp"

namespace {

double peak_rss_mb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

/// bench_python.py's blob: exp(-3 ((x - 0.3)^2 + 2 (y + 0.2)^2 + 0.5 z^2)) on [-1, 1]^3.
std::vector<double> blob(int n) {
    std::vector<double> values(static_cast<std::size_t>(n) * n * n);
    const auto at = [n](int i) { return -1.0 + 2.0 * i / (n - 1); };
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const double x = at(i) - 0.3, y = at(j) + 0.2, z = at(k);
                values[(static_cast<std::size_t>(k) * n + j) * n + i] =
                    std::exp(-(x * x + 2.0 * y * y + 0.5 * z * z) * 3.0);
            }
        }
    }
    return values;
}

}  // namespace

int main(int argc, char** argv) {
    int size = 256, image = 256, repeats = 5;
    std::string archive = "bench_python_baseline.cdb";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string flag = argv[i], value = argv[i + 1];
        if (flag == "--size") size = std::stoi(value);
        if (flag == "--image") image = std::stoi(value);
        if (flag == "--repeats") repeats = std::stoi(value);
        if (flag == "--archive") archive = value;
    }
    const std::string config = R"({"fields": ["v"], "views": [{"size": [)" + std::to_string(image) +
                               ", " + std::to_string(image) +
                               R"(]}], "every": 1, "volume": false, "on_existing": "replace", )" +
                               R"("archive": ")" + archive + R"("})";
    auto instrument = insitu::Instrument::from_json_text(config, {true, false, nullptr});
    const std::vector<double> values = blob(size);
    const insitu::Field field("v", values.data(), insitu::ScalarType::float64, {size, size, size});
    const double rss_before = peak_rss_mb();
    std::vector<double> ms;
    for (int r = 0; r <= repeats; ++r) {  // call 0 builds the kernels: left out
        const auto start = std::chrono::steady_clock::now();
        instrument->execute(r, r, {field});
        const std::chrono::duration<double, std::milli> took =
            std::chrono::steady_clock::now() - start;
        if (r > 0) ms.push_back(took.count());
    }
    instrument->finalize();
    std::printf("{\"ms\": [");
    for (std::size_t r = 0; r < ms.size(); ++r) std::printf("%s%.3f", r ? ", " : "", ms[r]);
    std::printf("], \"rss_before_mb\": %.1f, \"peak_rss_mb\": %.1f}\n", rss_before, peak_rss_mb());
    return 0;
}
