// bench_marching: what the ray-marching passes cost against the volume's and the image's size,
// and how far each is from what the machine could do (issue 13).
//
// Four passes on a Marschner-Lobb volume (structure throughout the box, nothing to skip), one
// semi-transparent 1D transfer function, 1-voxel step, every ray marched over its whole span
// (early termination off, empty-space skipping off), so the counted samples are the samples taken:
//   truth_unshaded  ground truth (VolumeRenderer), no shading
//   truth_shaded    ground truth, Phong shading (a gradient per sample)
//   single          single-perspective proxies: 4 depth layers, L = 16 uniform intervals,
//                   attenuation + mean depth, in one pass
//   multi           the same proxies from the volume distortion camera (45 degree tilt)
// Sweep "volume": side 64-512 at a 512^2 image; sweep "image": 128^2-1024^2 at 256^3; sweep
// "bookkeeping": single-perspective proxies at 256^3 / 512^2 with L = 4, 16, 64 and 1, 4, 8 layers,
// beside the unshaded ground truth of the same frame.
// Per point: ms per frame, best of --repeats frames after one warm-up, with the median and the
// maximum (a shared machine is noisy: the best shows what a quiet one does, the spread how noisy
// it was; the points of a group are timed in interleaved rounds, see bench::interleaved_timings),
// the samples counted on the host with the renderers' rule (sample_count.hpp), M samples/s and ns
// per sample. Before the runs it states a machine model (loads and instructions per sample,
// counted from the kernels; hardware threads, clock, SIMD width) and its bounds in M samples/s,
// and each row says what fraction of the scalar and of the SIMD bound it reaches.
//
// This program measures and prints; it asserts nothing and is never run as a test.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "arguments.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/layers.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "insitu/testing/analytic_fields.hpp"
#include "machine.hpp"
#include "median_time.hpp"
#include "sample_count.hpp"

namespace {

using namespace insitu;
using Clock = std::chrono::steady_clock;

// --- options ---------------------------------------------------------------------------------

struct Options {
    std::vector<int> volumes{64, 128, 256, 512};   ///< sweep "volume": cube sides
    std::vector<int> images{128, 256, 512, 1024};  ///< sweep "image": square image sides
    int base_volume = 256;  ///< the volume of sweeps "image" and "bookkeeping"
    int base_image = 512;   ///< the image of sweeps "volume" and "bookkeeping"
    int repeats = 5;
    double step_voxels = 1.0;
    double max_frame_s = 10.0;  ///< a point whose warm-up frame takes longer is skipped
    bool quick = false;
    bool lists_given = false;
    std::string csv;
};

std::vector<int> parse_sides(const std::string& flag, const std::string& text) {
    std::vector<int> sides;
    std::stringstream parts(text);
    std::string part;
    while (std::getline(parts, part, ',')) {
        sides.push_back(cli::parse_integer<int>(flag, part, 2, 4096, text));
    }
    if (sides.empty()) throw cli::UsageError(flag + ": expected a list such as 64,128");
    return sides;
}

const cli::CommandHelp& command_help() {
    static const cli::CommandHelp help = [] {
        const Options defaults;
        return cli::CommandHelp{
            "bench_marching [options]",
            "Times the ground truth (unshaded, shaded) and the single- and multi-perspective "
            "proxy passes on a Marschner-Lobb volume against volume size (64^3-512^3 at 512^2) and "
            "image size (128^2-1024^2 at 256^3), and the proxies' per-sample bookkeeping "
            "(L intervals, layers) at 256^3 / 512^2; prints ms (best of N, median, max), counted "
            "samples, M samples/s, ns per sample, and each against a machine model's scalar and "
            "SIMD bounds.",
            {{"--quick", "", "volumes 64-256 and images 128-512 only (a few minutes)", ""},
             {"--volumes", "LIST", "sides of sweep \"volume\", comma-separated", "64,128,256,512"},
             {"--images", "LIST", "image sides of sweep \"image\", comma-separated",
              "128,256,512,1024"},
             {"--base-volume", "N", "volume side of sweeps \"image\" and \"bookkeeping\"",
              std::to_string(defaults.base_volume)},
             {"--base-image", "P", "image side of sweeps \"volume\" and \"bookkeeping\"",
              std::to_string(defaults.base_image)},
             {"--repeats", "N", "timed frames per point after one warm-up frame",
              std::to_string(defaults.repeats)},
             {"--step", "VOXELS", "ray step in voxels", cli::default_text(defaults.step_voxels)},
             {"--max-frame-s", "S", "skip a point whose warm-up frame takes longer than S s",
              cli::default_text(defaults.max_frame_s)},
             {"--csv", "FILE", "also write every point as CSV (columns in bench/README.md)", ""}},
            "No timed assertions: it measures and prints. Run it niced on a shared machine "
            "(nice -n 19). INSITU_OPENCL_DEVICE picks the device. Exit status 1 when a pass "
            "fails, 2 for bad options."};
    }();
    return help;
}

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        if (flag == "--quick") {
            options.quick = true;
            continue;
        }
        static const std::vector<std::string> kValueFlags{
            "--volumes", "--images", "--base-volume", "--base-image",
            "--repeats", "--step",   "--max-frame-s", "--csv"};
        if (std::find(kValueFlags.begin(), kValueFlags.end(), flag) == kValueFlags.end()) {
            throw cli::UsageError("unknown option \"" + flag + "\"");
        }
        const std::string value = cli::next_value(argc, argv, i);
        if (flag == "--volumes") {
            options.volumes = parse_sides(flag, value);
            options.lists_given = true;
        } else if (flag == "--images") {
            options.images = parse_sides(flag, value);
            options.lists_given = true;
        } else if (flag == "--base-volume") {
            options.base_volume = cli::parse_integer<int>(flag, value, 2, 4096);
        } else if (flag == "--base-image") {
            options.base_image = cli::parse_integer<int>(flag, value, 1, 16384);
        } else if (flag == "--repeats") {
            options.repeats = cli::parse_integer<int>(flag, value, 1, 1000);
        } else if (flag == "--step") {
            options.step_voxels = cli::parse_finite(flag, value);
            if (!(options.step_voxels > 0.0)) throw cli::UsageError(flag + ": expected > 0");
        } else if (flag == "--max-frame-s") {
            options.max_frame_s = cli::parse_finite(flag, value);
            if (!(options.max_frame_s > 0.0)) throw cli::UsageError(flag + ": expected > 0");
        } else {  // --csv, the last of kValueFlags
            if (value.empty()) throw cli::UsageError(flag + ": expected a file name");
            options.csv = value;
        }
    }
    if (options.quick && options.lists_given) {
        throw cli::UsageError("--quick chooses the sweeps' sides; give it or the lists, not both");
    }
    if (options.quick) {
        options.volumes = {64, 128, 256};
        options.images = {128, 256, 512};
    }
    return options;
}

// --- the machine model -----------------------------------------------------------------------
//
// Per sample, counted by hand from kernels/render/ray_march.cl (march step, sample_trilinear,
// lookup_transfer, absorb), volume_renderer.cl (compositing, shading) and proxy_renderer.cl
// (layers, intervals) as x86 instructions of the one-ray-per-work-item kernels (render_volume,
// render_proxies: what blocks of a distributed run and ray_packets = false take), which PoCL runs
// as scalar code (one ray per loop iteration: it does not vectorise across work-items a loop with
// a data-dependent trip count, bench/README.md). A float4 operation counts as one 128-bit
// instruction, an FMA as one, each load as its own instruction (x86 may fold some into
// arithmetic), tests of loop-invariant flags once each. Two bounds follow: (a) that scalar code
// at the core's issue width; (b) the same work 16 rays to a vector (a ray packet, as the packet
// kernels that march whole volumes do), arithmetic perfectly vectorised and every per-ray load a
// gathered element. A packet kernel that does less work per sample than the scalar one (fewer
// gathers for the gradient, say) can exceed (b). Approximate by construction, perhaps +-30 %:
// estimates, not limits.

struct Cost {
    double instructions = 0.0;  ///< scalar code, per sample
    double loads = 0.0;         ///< load instructions (a float4 table entry is one)
    double stores = 0.0;
    /// Loads and stores of a 16-wide version, per sample: values that differ per ray become one
    /// gathered (or scattered) element each; loads the same for every ray (isovalues, interval
    /// edges) are broadcast once per vector and drop out.
    double element_loads = 0.0;
    double element_stores = 0.0;

    constexpr Cost operator+(const Cost& o) const {
        return {instructions + o.instructions, loads + o.loads, stores + o.stores,
                element_loads + o.element_loads, element_stores + o.element_stores};
    }
    constexpr Cost operator*(double n) const {
        return {instructions * n, loads * n, stores * n, element_loads * n, element_stores * n};
    }
};

// The march step: sample_t ((float)i, + 0.5, fma with step and t_near: 3), t >= t_far (compare,
// branch: 2), sample_position_voxels (3 fma + 3 sub: 6), ++i and the loop's jump (2) = 13.
constexpr Cost kMarchStep{13, 0, 0, 0, 0};
// sample_trilinear: float: 3 clamps (min + max: 6), 3 fractions (3), 7 mix (a + (b - a) t: sub +
// fma: 14) = 23; integer: 3 float->int, 3 int min, 3 int->float, the corner's index (2 multiplies,
// 2 adds) = 13; the 8 corner loads: 23 + 13 + 8 = 44.
constexpr int kTrilinearVolumeLoads = 8;
constexpr Cost kTrilinear{44, kTrilinearVolumeLoads, 0, kTrilinearVolumeLoads, 0};
// lookup_transfer, 1D table: (value - min) * scale (2), clamp (2), * (bins - 1) (1), float->int,
// int min, int->float, fraction (4), the bins.y == 1 branch (1), 2 float4 loads (table[ix],
// table[ix + 1]: 2), float4 mix (sub + fma: 2) = 14. A 16-wide version gathers each of the 2
// entries' 4 components: 8 element loads.
constexpr int kTransferEntries = 2;
constexpr int kTransferFloatsPerEntry = 4;
constexpr Cost kTransfer{14, kTransferEntries, 0, kTransferEntries* kTransferFloatsPerEntry, 0};
// Ground-truth compositing (volume_renderer.cl): isnan(value) (2), .w extract + alpha <= 0 (3),
// isinf(depth) (2), absorb (T alpha, 1 - alpha, T *= : 3), colour += weight rgb (broadcast +
// float4 fma: 2), 1 - T >= stop (sub, compare, branch: 3) = 15.
constexpr Cost kComposite{15, 0, 0, 0, 0};
// Shading adds (volume_renderer.cl): gradient_central's 6 trilinear samples, each at p +- one
// axis (1 add each), the 3 differences and the scale (6), length (3 fma/mul + sqrt: 4), isfinite
// (2), gm > 1e-12 (2), normalise (div + 3 mul: 4), dot with the light (3), fabs (1), pow (~40:
// log2, multiply, exp2 as a library call), colour (a + b n.l) + c pow (broadcasts + float4 fma and
// mul: 4) = 6 x (44 + 1) + 66 = 336 instructions; 48 more volume loads.
constexpr int kGradientSamples = 6;
constexpr double kPowInstructions = 40;
constexpr Cost kShading =
    kTrilinear * kGradientSamples +
    Cost{kGradientSamples + 6 + 4 + 2 + 2 + 4 + 3 + 1 + kPowInstructions + 4, 0, 0, 0, 0};
// The proxy pass's per-sample bookkeeping (proxy_renderer.cl), beyond the same march step,
// trilinear sample and table lookup: loop-invariant flag tests (partial twice, find_crossings,
// want_segments, want_mean_depth, want_optical_depth, block_size, the segment tests: ~10),
// isnan (2), !isnan(previous) (2), accumulating || ... (2), alpha > 0 && accumulating (3),
// uniform interval: scale > 0 (2), load edges[0] (1: global memory the kernel also writes, so
// not hoisted), sub, mul, float->int, clamp (2 int: 5), absorb (3), attenuation[j] += weight
// (address, load, add, store: 4), weighted_depth[j] += weight * depth (depth fma, load, fma,
// store: 4), 1 - T >= stop (3), the break test (~4) = 45. Scalar loads: edges[0] and the two
// accumulators; 16-wide: edges[0] is broadcast, the accumulators a gather and a scatter each.
constexpr Cost kProxyBookkeeping{45, 3, 2, 2, 2};
// Per depth layer and sample (the crossing loop): its trip (increment, compare, branch: 3), load
// layer_t[l], isinf, branch (3); once a layer is found the && stops there, which on this scene is
// most samples (the isovalues are crossed near the front); before, 4 more and the isovalue's
// load. Counted found: 6 instructions, 1 load (a 16-wide version keeps layer_t in registers).
constexpr Cost kPerLayer{6, 1, 0, 0, 0};

Cost truth_cost(bool shaded) {
    const Cost unshaded = kMarchStep + kTrilinear + kTransfer + kComposite;
    return shaded ? unshaded + kShading : unshaded;
}

Cost proxy_cost(int layers) {
    return kMarchStep + kTrilinear + kTransfer + kProxyBookkeeping + kPerLayer * layers;
}

// Machine assumptions (printed and in bench/README.md).
constexpr double kScalarIpc = 4.0;  ///< Skylake-SP's issue width: a ceiling; such code does 2-3
constexpr double kVectorIpc = 2.0;  ///< two 512-bit ALU/FMA ports per core
constexpr double kLoadsPerCycle = 2.0;
constexpr double kStoresPerCycle = 1.0;
/// A gather or scatter costs a load (store) slot per element: 16 lanes take 8 cycles of the two
/// load ports. Hardware that gathers faster raises the SIMD bound in proportion.
constexpr double kGatherElementsPerCycle = kLoadsPerCycle;
constexpr double kScatterElementsPerCycle = kStoresPerCycle;

struct Machine {
    unsigned threads = 1;
    double ghz = 0.0;
    std::string clock_source;
    int simd_floats = 4;
    std::string simd_name;
};

#if defined(__x86_64__) || defined(__i386__)
/// The core's clock from a chain of 8 dependent instructions per iteration of `kind`: "add"
/// (x += y, one cycle each on every x86 core of this century; y is a register, because recent
/// Intel cores fold chains of add-immediate at rename: 21 "GHz" on this machine's) or "imul"
/// (x *= x, three cycles each), so cycles / seconds is the clock while this core runs this code,
/// turbo included. Best of 5 short trials: a busy machine only slows it.
double dependent_chain_ghz(bool multiply) {
    constexpr std::uint64_t kIterations = 10'000'000;
    constexpr double kInstructionsPerIteration = 8.0;
    const double cycles_each = multiply ? 3.0 : 1.0;
    double best = 0.0;
    for (int trial = 0; trial < 5; ++trial) {
        std::uint64_t x = 3;
        std::uint64_t y = static_cast<std::uint64_t>(trial) + 1;
        const auto start = Clock::now();
        for (std::uint64_t i = 0; i < kIterations; ++i) {
            // The loop counter runs beside this chain; the chain sets the pace.
            if (multiply) {
                asm volatile(
                    "imul %0, %0\n\timul %0, %0\n\timul %0, %0\n\timul %0, %0\n\t"
                    "imul %0, %0\n\timul %0, %0\n\timul %0, %0\n\timul %0, %0"
                    : "+r"(x));
            } else {
                asm volatile(
                    "add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\t"
                    "add %1, %0\n\tadd %1, %0\n\tadd %1, %0\n\tadd %1, %0"
                    : "+r"(x)
                    : "r"(y));
            }
        }
        const double ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count();
        best = std::max(best, kIterations * kInstructionsPerIteration * cycles_each / ns);
    }
    return best;
}
#endif

/// "cpu MHz" of /proc/cpuinfo's first processor in GHz, 0 when there is none (the nominal or
/// last sampled clock, as the kernel reports it; a VM often reports the host's base clock).
double cpuinfo_ghz() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("cpu MHz", 0) != 0) continue;
        const auto colon = line.find(':');
        if (colon == std::string::npos) break;
        double mhz = 0.0;
        std::istringstream(line.substr(colon + 1)) >> mhz;
        return mhz / 1000.0;
    }
    return 0.0;
}

Machine measure_machine() {
    Machine machine;
    machine.threads = std::max(1u, std::thread::hardware_concurrency());
#if defined(__x86_64__) || defined(__i386__)
    const double measured = dependent_chain_ghz(false);
    const double check = dependent_chain_ghz(true);
    // Outside this range, or far from the multiply chain's figure, the loop was disturbed or the
    // core is not what the model assumes: /proc/cpuinfo then.
    if (measured > 0.5 && measured < 7.0 && std::abs(measured / check - 1.0) < 0.15) {
        machine.ghz = measured;
        char source[128];
        std::snprintf(source, sizeof source,
                      "measured: dependent-add loop, one thread; imul chain %.2f GHz", check);
        machine.clock_source = source;
    }
    if (__builtin_cpu_supports("avx512f")) {
        machine.simd_floats = 16;
        machine.simd_name = "AVX-512";
    } else if (__builtin_cpu_supports("avx2")) {
        machine.simd_floats = 8;
        machine.simd_name = "AVX2";
    } else {
        machine.simd_name = "SSE";
    }
#else
    machine.simd_name = "assumed 128-bit";
#endif
    if (machine.ghz == 0.0) {
        machine.ghz = cpuinfo_ghz();
        machine.clock_source = "/proc/cpuinfo \"cpu MHz\"";
    }
    if (machine.ghz == 0.0) {
        machine.ghz = 2.0;
        machine.clock_source = "unknown, assumed 2 GHz";
    }
    return machine;
}

struct Bounds2 {
    double scalar = 0.0;  ///< M samples/s
    double simd = 0.0;
};

Bounds2 bounds_of(const Cost& cost, const Machine& machine) {
    const double cycles_per_second = machine.threads * machine.ghz * 1e9;
    const double scalar_cycles =
        std::max({cost.instructions / kScalarIpc, cost.loads / kLoadsPerCycle,
                  cost.stores / kStoresPerCycle});
    // Perfect vectorisation of the arithmetic (no masking cost for rays that diverge) against
    // gathers and scatters priced per element: optimistic on the first, the model's point.
    const double simd_cycles = std::max({cost.instructions / machine.simd_floats / kVectorIpc,
                                         cost.element_loads / kGatherElementsPerCycle,
                                         cost.element_stores / kScatterElementsPerCycle});
    return {cycles_per_second / scalar_cycles / 1e6, cycles_per_second / simd_cycles / 1e6};
}

void print_machine(const Machine& machine, const std::string& device) {
    std::printf("device:  %s\n", device.c_str());
    std::printf(
        "machine: %u hardware threads (each counted as a core), %.2f GHz (%s), %s (%d "
        "floats)\n",
        machine.threads, machine.ghz, machine.clock_source.c_str(), machine.simd_name.c_str(),
        machine.simd_floats);
    std::printf(
        "model assumptions: scalar code at %.0f instructions per cycle (a ceiling: such code "
        "sustains\n  2-3, which halves the bound), %.0f loads and %.0f store per cycle per core; "
        "%d-wide\n  vectors at %.0f instructions per cycle, every per-ray load a gathered element "
        "at %.0f per cycle\n  (the load ports), every per-ray store a scattered element at %.0f "
        "per cycle; caches hit\n  (a ray's 8 corners share lines with its previous sample's). "
        "Counts by hand from the kernels,\n  +-30 %%.\n",
        kScalarIpc, kLoadsPerCycle, kStoresPerCycle, machine.simd_floats, kVectorIpc,
        kGatherElementsPerCycle, kScatterElementsPerCycle);
    std::printf(
        "per trilinear sample: %d volume loads, %d transfer-table entries (%d floats), "
        "%.0f instructions\n  for the march step + sample + lookup + compositing "
        "(ground truth, unshaded)\n",
        kTrilinearVolumeLoads, kTransferEntries, kTransferEntries * kTransferFloatsPerEntry,
        truth_cost(false).instructions);
    std::printf("\n%-26s %7s %6s %6s %9s %9s %13s %11s\n", "pass (per sample)", "instr", "loads",
                "stores", "el.loads", "el.stores", "scalar Ms/s", "SIMD Ms/s");
    struct Row {
        const char* name;
        Cost cost;
    };
    const Row rows[] = {{"truth_unshaded", truth_cost(false)},
                        {"truth_shaded", truth_cost(true)},
                        {"single/multi, 1 layer", proxy_cost(1)},
                        {"single/multi, 4 layers", proxy_cost(4)},
                        {"single/multi, 8 layers", proxy_cost(8)}};
    for (const Row& row : rows) {
        const Bounds2 bound = bounds_of(row.cost, machine);
        std::printf("%-26s %7.0f %6.0f %6.0f %9.0f %9.0f %13.1f %11.1f\n", row.name,
                    row.cost.instructions, row.cost.loads, row.cost.stores, row.cost.element_loads,
                    row.cost.element_stores, bound.scalar, bound.simd);
    }
}

// --- timing ----------------------------------------------------------------------------------

using bench::ms_since;
using bench::Timing;

// --- the sweeps ------------------------------------------------------------------------------

struct Point {
    std::string sweep;
    std::string pass;
    int volume = 0;
    int image = 0;
    int intervals = 0;  ///< 0 for the ground truth
    int layers = 0;
    std::uint64_t samples = 0;
    Timing timing;
    Bounds2 bound;
};

double msamples_per_s(const Point& p) {
    return static_cast<double>(p.samples) / (p.timing.best * 1e3);
}

void print_header() {
    std::printf("\n%-12s %-15s %6s %5s %3s %3s %11s %9s %9s %9s %8s %7s %7s %6s\n", "sweep", "pass",
                "volume", "image", "L", "K", "samples", "ms best", "median", "max", "Ms/s",
                "ns/smp", "%scalar", "%SIMD");
}

void print_point(const Point& p) {
    std::printf("%-12s %-15s %6d %5d %3d %3d %11llu", p.sweep.c_str(), p.pass.c_str(), p.volume,
                p.image, p.intervals, p.layers, static_cast<unsigned long long>(p.samples));
    if (p.timing.skipped) {
        std::printf("  skipped: the warm-up frame took %.1f s\n", p.timing.warmup / 1e3);
    } else {
        const double rate = msamples_per_s(p);
        std::printf(" %9.1f %9.1f %9.1f %8.1f %7.2f %6.0f%% %5.0f%%\n", p.timing.best,
                    p.timing.median, p.timing.worst, rate,
                    p.timing.best * 1e6 / static_cast<double>(p.samples),
                    100.0 * rate / p.bound.scalar, 100.0 * rate / p.bound.simd);
    }
    std::fflush(stdout);
}

/// vtk_peer.cpp's transfer function: semi-transparent throughout, opacity 0 only at the lowest
/// value, so (nearly) every sample composites and, shaded, is lit. Its opacities are per voxel of
/// the 256^3 grid on Marschner-Lobb's [-1, 1] box at every volume size, so a larger volume takes
/// more, thinner samples of the same picture.
TransferFunction bench_transfer_function() {
    return TransferFunction({{0.0, {0.1f, 0.2f, 0.9f, 0.0f}},
                             {0.3, {0.1f, 0.8f, 0.9f, 0.01f}},
                             {0.6, {0.9f, 0.9f, 0.2f, 0.04f}},
                             {1.0, {0.9f, 0.2f, 0.1f, 0.1f}}},
                            2.0 / 255.0);
}

/// `count` isovalues evenly from 0.3 to 0.75; 4 gives the issue's {0.3, 0.45, 0.6, 0.75}.
std::vector<double> isovalues(int count) {
    if (count == 1) return {0.45};
    std::vector<double> values;
    for (int l = 0; l < count; ++l) values.push_back(0.3 + 0.45 * l / (count - 1));
    return values;
}

class Bench {
public:
    Bench(const Options& options, const Machine& machine) : options_(options), machine_(machine) {}

    /// Every point of the sweeps that use a volume of side `side`.
    void run_volume(int side) {
        const auto make_start = Clock::now();
        const SampledVolume volume = make_marschner_lobb(side);
        const double make_s = ms_since(make_start) / 1e3;
        ProxyRenderer proxies;
        const auto upload_start = Clock::now();
        proxies.upload(volume.field());
        std::printf("\n(Marschner-Lobb %d^3 float32: made in %.1f s, uploaded in %.0f ms)\n", side,
                    make_s, ms_since(upload_start));
        print_header();

        const bool in_volume_sweep = std::find(options_.volumes.begin(), options_.volumes.end(),
                                               side) != options_.volumes.end();
        const bool is_base = side == options_.base_volume;
        if (in_volume_sweep) {
            const std::vector<Point> points =
                four_passes(proxies, "volume", side, options_.base_image);
            // The same frame is sweep "image"'s point at the base image: measured once.
            if (is_base) {
                for (Point p : points) {
                    p.sweep = "image";
                    record(p, false);
                }
            }
        }
        if (is_base) {
            for (int image : options_.images) {
                if (in_volume_sweep && image == options_.base_image) continue;
                four_passes(proxies, "image", side, image);
            }
            bookkeeping(proxies, side, options_.base_image);
        }
    }

    const std::vector<Point>& points() const { return points_; }

private:
    struct Frame {
        Camera camera;
        DistortionCamera distortion;
        std::uint64_t single_samples;
        std::uint64_t multi_samples;
    };

    Frame frame_of(const ProxyRenderer& proxies, int image) const {
        OrbitView view;
        view.azimuth_deg = 30.0;
        view.elevation_deg = 20.0;
        view.width = image;
        view.height = image;
        const Bounds& box = proxies.volume().bounds;
        const Camera camera = Camera::orbit(view, box);
        const DistortionCamera distortion = DistortionCamera::orbit(view, box, 45.0);
        // The field's smallest spacing times the step, as both renderers take it.
        const double step = proxies.volume().step_world(options_.step_voxels);
        return {camera, distortion, bench::samples_per_frame(camera, image, image, box, step),
                bench::samples_per_frame(distortion, image, image, box, step)};
    }

    ProxyRequest request_of(const ProxyRenderer& proxies, int intervals, int layers) const {
        ProxyRequest request;
        request.isovalues = isovalues(layers);
        request.intervals = proxies.choose_intervals(intervals, IntervalMode::uniform);
        request.transfer_function = tf_;
        // Every ray over its whole span: the counted samples are the samples taken.
        request.skip_empty_space = false;
        request.march.step_voxels = options_.step_voxels;
        request.march.early_termination_opacity = 2.0;  // > 1 disables (RenderSettings)
        return request;
    }

    void record(Point p, bool print = true) {
        if (print) print_point(p);
        points_.push_back(std::move(p));
    }

    /// Points measured together (bench::interleaved_timings) and their frames.
    struct Group {
        std::vector<Point> points;
        std::vector<std::function<void()>> frames;

        void add(Point point, const Cost& cost, const Machine& machine,
                 std::function<void()> frame) {
            point.bound = bounds_of(cost, machine);
            points.push_back(std::move(point));
            frames.push_back(std::move(frame));
        }
    };

    std::vector<Point> measure(Group group) {
        const std::vector<Timing> timings =
            bench::interleaved_timings(options_.repeats, group.frames, options_.max_frame_s * 1e3);
        for (std::size_t i = 0; i < group.points.size(); ++i) {
            group.points[i].timing = timings[i];
            record(group.points[i]);
        }
        return group.points;
    }

    static RenderSettings truth_settings(double step_voxels, bool shaded) {
        RenderSettings settings;
        settings.step_voxels = step_voxels;
        settings.shading = shaded;
        settings.early_termination_opacity = 2.0;  // > 1 disables (RenderSettings)
        return settings;
    }

    std::vector<Point> four_passes(ProxyRenderer& proxies, const std::string& sweep, int side,
                                   int image) {
        const Frame frame = frame_of(proxies, image);
        const RenderSettings unshaded = truth_settings(options_.step_voxels, false);
        const RenderSettings shaded = truth_settings(options_.step_voxels, true);
        const ProxyRequest request = request_of(proxies, kIntervals, kLayers);
        Group group;
        group.add({sweep, "truth_unshaded", side, image, 0, 0, frame.single_samples, {}, {}},
                  truth_cost(false), machine_,
                  [&] { proxies.render_ground_truth(frame.camera, tf_, unshaded); });
        group.add({sweep, "truth_shaded", side, image, 0, 0, frame.single_samples, {}, {}},
                  truth_cost(true), machine_,
                  [&] { proxies.render_ground_truth(frame.camera, tf_, shaded); });
        group.add({sweep, "single", side, image, kIntervals, kLayers, frame.single_samples, {}, {}},
                  proxy_cost(kLayers), machine_, [&] { proxies.render(frame.camera, request); });
        group.add({sweep, "multi", side, image, kIntervals, kLayers, frame.multi_samples, {}, {}},
                  proxy_cost(kLayers), machine_,
                  [&] { proxies.render(frame.distortion, request); });
        return measure(std::move(group));
    }

    void bookkeeping(ProxyRenderer& proxies, int side, int image) {
        const Frame frame = frame_of(proxies, image);
        const RenderSettings unshaded = truth_settings(options_.step_voxels, false);
        Group group;
        // The reference: the same samples without any proxy bookkeeping.
        group.add(
            {"bookkeeping", "truth_unshaded", side, image, 0, 0, frame.single_samples, {}, {}},
            truth_cost(false), machine_,
            [&] { proxies.render_ground_truth(frame.camera, tf_, unshaded); });
        std::vector<ProxyRequest> requests;
        requests.reserve(9);  // the frames refer to them
        for (int intervals : {4, 16, kMaxIntervals}) {
            for (int layers : {1, 4, 8}) {
                const ProxyRequest* request =
                    &requests.emplace_back(request_of(proxies, intervals, layers));
                group.add({"bookkeeping",
                           "single",
                           side,
                           image,
                           intervals,
                           layers,
                           frame.single_samples,
                           {},
                           {}},
                          proxy_cost(layers), machine_,
                          [&, request] { proxies.render(frame.camera, *request); });
            }
        }
        measure(std::move(group));
    }

    static constexpr int kIntervals = 16;
    static constexpr int kLayers = 4;
    static_assert(kMaxIntervals >= 64, "sweep bookkeeping asks for 64 intervals");
    static_assert(kMaxLayers >= 8, "sweep bookkeeping asks for 8 layers");

    const Options& options_;
    const Machine& machine_;
    const TransferFunction tf_ = bench_transfer_function();
    std::vector<Point> points_;
};

/// The sweeps' rows in sweep order (volume, image, bookkeeping), each in the order measured.
std::vector<Point> in_sweep_order(const std::vector<Point>& points) {
    std::vector<Point> ordered;
    for (const char* sweep : {"volume", "image", "bookkeeping"}) {
        for (const Point& p : points) {
            if (p.sweep == sweep) ordered.push_back(p);
        }
    }
    // Within a sweep: by the swept size, then the order the passes were measured in.
    std::stable_sort(ordered.begin(), ordered.end(), [](const Point& a, const Point& b) {
        if (a.sweep != b.sweep) return false;
        if (a.sweep == "volume") return a.volume < b.volume;
        if (a.sweep == "image") return a.image < b.image;
        return false;
    });
    return ordered;
}

void write_csv(const std::string& path, const std::vector<Point>& points) {
    std::ofstream out(path);
    if (!out) throw IoError("cannot write " + path);
    out << "sweep,pass,volume,image,intervals,layers,samples,ms_best,ms_median,ms_max,"
           "msamples_per_s,ns_per_sample\n";
    for (const Point& p : points) {
        if (p.timing.skipped) continue;
        char line[256];
        std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%d,%llu,%.3f,%.3f,%.3f,%.3f,%.4f\n",
                      p.sweep.c_str(), p.pass.c_str(), p.volume, p.image, p.intervals, p.layers,
                      static_cast<unsigned long long>(p.samples), p.timing.best, p.timing.median,
                      p.timing.worst, msamples_per_s(p),
                      p.timing.best * 1e6 / static_cast<double>(p.samples));
        out << line;
    }
    if (!out.flush()) throw IoError("cannot write " + path);
}

int run(const Options& options) {
    const auto start = Clock::now();
    const Machine machine = measure_machine();
    insitu::bench::print_machine("start");
    print_machine(machine, ComputeDevice::shared()->description());
    std::printf(
        "\nscene: Marschner-Lobb on [-1, 1]^3, orthographic orbit view (azimuth 30, "
        "elevation 20 degrees),\n  step %.3g voxels, early termination and empty-space "
        "skipping off; ms: best of %d after 1 warm-up\n  (median and max beside it); "
        "proxies: L uniform intervals, K depth layers, attenuation + mean depth\n",
        options.step_voxels, options.repeats);

    std::vector<int> sides = options.volumes;
    sides.push_back(options.base_volume);
    std::sort(sides.begin(), sides.end());
    sides.erase(std::unique(sides.begin(), sides.end()), sides.end());
    Bench bench(options, machine);
    for (int side : sides) bench.run_volume(side);

    const std::vector<Point> ordered = in_sweep_order(bench.points());
    std::printf("\n=== all points, by sweep ===");
    print_header();
    for (const Point& p : ordered) print_point(p);
    if (!options.csv.empty()) {
        write_csv(options.csv, ordered);
        std::printf("\nwrote %s\n", options.csv.c_str());
    }
    std::printf("total %.0f s\n", ms_since(start) / 1e3);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (cli::answer_help({argv + 1, argv + argc}, command_help())) return 0;
    const Options options = cli::parse_or_exit("bench_marching", [&] { return parse(argc, argv); });
    try {
        return run(options);
    } catch (const std::exception& error) {
        std::fprintf(stderr, "bench_marching: %s\n", error.what());
        return 1;
    }
}
