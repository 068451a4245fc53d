#pragma once
// Constants that host code and kernels must agree on, each spelled once as a C++ constant and
// handed to every OpenCL build as a -D option (OpenClDevice::build_options), so a kernel never
// carries a hand-copied limit. Kernels refer to them by the names in kKernelConstants.
#include <array>
#include <cstdint>

#include "insitu/core/intervals.hpp"
#include "insitu/core/layers.hpp"
#include "insitu/core/light_field.hpp"
#include "insitu/explore/relighting.hpp"
#include "insitu/field.hpp"

namespace insitu::detail {

/// Bits of render_proxies' `wanted` argument (kernels/render/proxy_renderer.cl): which outputs
/// a pass computes; unrequested outputs get no device memory.
constexpr int kWantDepth = 1;
constexpr int kWantDistortion = 2;
constexpr int kWantAttenuation = 4;
constexpr int kWantMeanDepth = 8;
constexpr int kWantOpticalDepth = 16;
constexpr int kWantSegmentRgba = 32;
constexpr int kWantSegmentDepth = 64;
constexpr int kWantFirstHitDepth = 128;
/// A block's partial image in a distributed run: the fragment record of each pixel
/// (insitu/parallel/compositing.hpp), from which partial images composite exactly.
constexpr int kWantFragment = 256;
/// Per pixel, how many times the ray re-entered an interval it had already left (the
/// "interleaving" proxy: where it is 0, every interval is one contiguous run and opacity edits
/// are exact; insitu/explore/transfer_function_edit.hpp).
constexpr int kWantInterleaving = 512;
/// Per pixel and interval, the depth of the first sample that gave the interval light (the
/// "entry_depth" proxy: where its first run begins; the edit trust compares the intervals in
/// that order with the mean-depth order, transfer_function_edit.hpp).
constexpr int kWantEntryDepth = 1024;
/// A block's light-field pass reads, per pixel, the march's state where the ray enters the
/// block (kFrontChannels floats, insitu/parallel/light_field_compositing.hpp).
constexpr int kWantFront = 2048;
/// Per pixel, the depth where the whole ray's opacity first reaches a second, lower threshold
/// than the first hit's (ProxyRequest::rim_depth: the light field's rims), in the same pass.
constexpr int kWantRimDepth = 4096;
/// Transmittance in front, the entry segment's transmittance in front, the isovalues crossed in
/// front (bits), the value of the sample just in front (NaN when none adjoins).
constexpr int kFrontChannels = 4;
/// A block's interleaving record (kWantInterleaving with kWantFragment): re-entries and their
/// light counted from the block's entry, the intervals of its first and last run, whether that
/// last run re-enters within the block, then per interval the light of its first run in the
/// block (parallel/interleaving_fold.hpp).
constexpr int kInterleavingHead = 5;
/// Floats per pixel of that record (kernels/render/proxy_renderer.cl writes them).
constexpr int kFragmentChannels = 9;

/// render_proxies' `segment_rule` argument: SegmentRule as the kernel spells it.
constexpr int kSegmentsWholeRay = static_cast<int>(SegmentRule::whole_ray);
constexpr int kSegmentsLayers = static_cast<int>(SegmentRule::layers);
constexpr int kSegmentsOpacity = static_cast<int>(SegmentRule::opacity);

/// The device volume is stored in bricks of 2^kVolumeBrickShift samples a side (x fastest within
/// a brick, bricks x fastest): a cell's eight corners then usually share one or two cache lines
/// instead of four, which is what rays further apart than a voxel (coarse images of large
/// volumes) pay for. Host upload (DeviceVolume::upload) and every kernel that reads the volume
/// (volume_offset_* in kernels/device/common.cl) agree on it through this constant.
constexpr int kVolumeBrickShift = 2;
constexpr int kVolumeBrickSide = 1 << kVolumeBrickShift;

/// Bricks along an axis of `samples` samples, the last one padded (the kernels' volume_bricks).
constexpr std::int64_t volume_bricks(std::int64_t samples) {
    return (samples + kVolumeBrickSide - 1) / kVolumeBrickSide;
}

/// The index of sample (x, y, z) of a volume of `dims` samples in the bricked device buffer: the
/// host's volume_offset_x + volume_offset_y + volume_offset_z (kernels/device/common.cl), which
/// DeviceVolume::upload writes and tests read back.
constexpr std::int64_t volume_offset(const Index3& dims, std::int64_t x, std::int64_t y,
                                     std::int64_t z) {
    constexpr std::int64_t side = kVolumeBrickSide, brick = side * side * side;
    const std::int64_t bricks_x = volume_bricks(dims[0]), bricks_y = volume_bricks(dims[1]);
    return (x / side) * brick + x % side + (y / side) * brick * bricks_x + (y % side) * side +
           (z / side) * brick * bricks_x * bricks_y + (z % side) * side * side;
}

struct KernelConstant {
    const char* name;  ///< the macro the kernels use
    int value;
};

/// Every constant passed to the kernels. Private arrays are sized by the MAX_* limits, so they
/// bound each work-item's private memory.
inline constexpr std::array<KernelConstant, 22> kKernelConstants{{
    {"MAX_LAYERS", kMaxLayers},        // depth layers per pass (layer_t[] in the proxy kernel)
    {"MAX_INTERVALS", kMaxIntervals},  // intensity intervals (a[] in colour model, edits)
    {"MAX_LIGHTS", kMaxLights},        // lights per relighting call (half_vectors[])
    {"WANT_DEPTH", kWantDepth},
    {"WANT_DISTORTION", kWantDistortion},
    {"WANT_ATTENUATION", kWantAttenuation},
    {"WANT_MEAN_DEPTH", kWantMeanDepth},
    {"WANT_OPTICAL_DEPTH", kWantOpticalDepth},
    {"WANT_SEGMENT_RGBA", kWantSegmentRgba},
    {"WANT_SEGMENT_DEPTH", kWantSegmentDepth},
    {"WANT_FIRST_HIT_DEPTH", kWantFirstHitDepth},
    {"WANT_FRAGMENT", kWantFragment},
    {"WANT_INTERLEAVING", kWantInterleaving},
    {"WANT_ENTRY_DEPTH", kWantEntryDepth},
    {"WANT_FRONT", kWantFront},
    {"WANT_RIM_DEPTH", kWantRimDepth},
    {"FRAGMENT_CHANNELS", kFragmentChannels},
    {"INTERLEAVING_HEAD", kInterleavingHead},
    {"SEGMENTS_WHOLE_RAY", kSegmentsWholeRay},
    {"SEGMENTS_LAYERS", kSegmentsLayers},
    {"SEGMENTS_OPACITY", kSegmentsOpacity},
    {"VOLUME_BRICK_SHIFT", kVolumeBrickShift},
}};

// Archive channel names number intervals with two digits ("attenuation.a07").
static_assert(kMaxIntervals >= 1 && kMaxIntervals <= 99, "interval channels have two digits");
static_assert(kMaxLayers >= 1 && kMaxLayers <= 64, "layer_t[] is a private array per work-item");
static_assert(kMaxLights >= 1 && kMaxLights <= 64, "half_vectors[] is a private array per pixel");
// The wanted bits must be distinct powers of two.
static_assert((kWantDepth | kWantDistortion | kWantAttenuation | kWantMeanDepth |
               kWantOpticalDepth | kWantSegmentRgba | kWantSegmentDepth | kWantFirstHitDepth |
               kWantFragment | kWantInterleaving | kWantEntryDepth | kWantFront | kWantRimDepth) ==
                  8191,
              "wanted bits are the thirteen distinct low bits");
static_assert(kSegmentsWholeRay != kSegmentsLayers && kSegmentsLayers != kSegmentsOpacity &&
                  kSegmentsWholeRay != kSegmentsOpacity,
              "the kernel tells the segment rules apart by these values");

}  // namespace insitu::detail
