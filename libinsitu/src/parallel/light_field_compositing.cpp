#include "insitu/parallel/light_field_compositing.hpp"

#include <bitset>
#include <cmath>
#include <limits>
#include <optional>

#include "core/elapsed.hpp"
#include "device/kernel_constants.hpp"
#include "insitu/parallel/compositing.hpp"
#include "parallel/scan_send.hpp"

namespace insitu {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kFrontChannels = detail::kFrontChannels;
// The fragment's channels read here (kernels/render/proxy_renderer.cl writes them).
enum : int { kFirstIndex = 0, kLastIndex = 1, kFirstValue = 2, kLastValue = 3, kRayT = 8 };

const float* fragment_of(const ProxyFrame* partial, std::int64_t pixel) {
    if (partial == nullptr) return nullptr;
    const float* fragment = &partial->fragment.pixels[pixel * detail::kFragmentChannels];
    return fragment[kFirstIndex] >= 0.0f ? fragment : nullptr;
}

// Whether the block has a record for `pixel`; if so, its ray order goes first in `record`.
bool starts_record(const ProxyFrame* partial, std::int64_t pixel, float* record) {
    const float* fragment = fragment_of(partial, pixel);
    if (fragment != nullptr) record[0] = fragment[kFirstIndex];
    return fragment != nullptr;
}

// The exchanges of one camera pass, timed; a rank's failing march is kept for the end.
struct Exchanges {
    Communicator& communicator;
    std::int64_t pixels;
    int root;
    double seconds = 0.0;
    std::exception_ptr failure;

    std::optional<ProxyFrame> march(const BlockPass& pass, const ProxyRequest& request) {
        if (!pass || failure) return std::nullopt;
        try {
            return pass(request);
        } catch (...) {
            failure = std::current_exception();
            return std::nullopt;
        }
    }
    std::vector<float> scan(const detail::ScanShape& shape, const detail::ScanPack& pack,
                            const detail::ScanFold& fold, const std::vector<float>& identity,
                            const std::vector<float>& no_reply, const detail::ScanUnpack& unpack) {
        const auto start = SteadyClock::now();
        std::vector<float> replies;
        try {
            replies = detail::scan_send(communicator, pixels, shape, root, pack, fold, identity,
                                        no_reply, unpack);
        } catch (...) {
            if (!failure) failure = std::current_exception();
            replies.assign(static_cast<std::size_t>(pixels) * shape.reply, 0.0f);
        }
        seconds += seconds_since(start);
        return replies;
    }
};

// 1. Per pixel of this rank's block, the state in front of it (ProxyRequest::front).
Image find_fronts(Exchanges& exchanges, const ProxyFrame* partial, const Camera& camera,
                  const std::vector<double>& isovalues) {
    const int layers = static_cast<int>(isovalues.size());
    const auto pack = [&](std::int64_t pixel, float* record) {
        const float* fragment = fragment_of(partial, pixel);
        if (fragment == nullptr) return false;
        std::copy(fragment, fragment + 4, record);  // first, last index; first, last value
        record[4] = fragment[kRayT];
        int crossed = 0;
        for (int l = 0; l < layers; ++l) {
            if (!std::isinf(partial->depth_layers[l].pixels[pixel])) crossed |= 1 << l;
        }
        record[5] = static_cast<float>(crossed);
        return true;
    };
    const auto fold = [&](const std::vector<const float*>& records,
                          const std::vector<float*>& replies, float*) {
        float transmittance = 1.0f;
        int crossed = 0;
        const float* front = nullptr;
        for (std::size_t r = 0; r < records.size(); ++r) {
            const float* block = records[r];
            const bool adjoins = front != nullptr && block[kFirstIndex] == front[kLastIndex] + 1.0f;
            const float before = adjoins ? front[kLastValue] : kNaN;
            const float after = block[kFirstValue];
            const float answer[kFrontChannels] = {transmittance, 1.0f, static_cast<float>(crossed),
                                                  before};
            std::copy(answer, answer + kFrontChannels, replies[r]);
            // A crossing between the front's last sample and this block's first is this block's
            // (its march compares that pair), and in front of every block behind it.
            for (int l = 0; l < layers && !std::isnan(before) && !std::isnan(after); ++l) {
                const auto iso = static_cast<float>(isovalues[l]);
                if ((before >= iso) != (after >= iso)) crossed |= 1 << l;
            }
            crossed |= static_cast<int>(block[5]);
            transmittance *= block[4];
            front = block;
        }
    };
    const std::vector<float> none = {1.0f, 1.0f, 0.0f, kNaN};
    Image fronts(camera.width(), camera.height(), kFrontChannels);
    fronts.pixels = exchanges.scan({6, kFrontChannels, 0}, pack, fold, {}, none,
                                   [](std::int64_t, std::int64_t, const float*) {});
    return fronts;
}

// The segment a ray enters a block in, from the state in front (as the kernel finds it).
int entry_segment(const ProxyRequest& request, int segments, const float* front) {
    if (request.segments == SegmentRule::layers) {
        return static_cast<int>(std::bitset<32>(static_cast<unsigned>(front[2])).count());
    }
    int segment = 0;
    while (request.segments == SegmentRule::opacity && segment + 1 < segments &&
           1.0f - front[0] >= static_cast<float>(request.segment_thresholds[segment])) {
        ++segment;
    }
    return segment;
}

// 2. Segment colours "over" in ray order and the front-most first hit and rim hit (each block's
// taken at the ray's opacity, its march starting from the transmittance in front), at the root;
// each block learns its entry segment's transmittance in front (fronts' channel 1). Records:
// ray order, entry segment, first hit, rim hit, the segments' RGBA.
void composite_segments(Exchanges& exchanges, const ProxyFrame* partial,
                        const ProxyRequest& request, int segments, Image& fronts,
                        ProxyFrame& frame) {
    const int S = segments;
    const auto pack = [&](std::int64_t pixel, float* record) {
        if (!starts_record(partial, pixel, record)) return false;
        record[1] =
            static_cast<float>(entry_segment(request, S, &fronts.pixels[pixel * kFrontChannels]));
        const auto hit = [pixel](const Image& depth) {
            return depth.pixels.empty() ? kInf : depth.pixels[pixel];
        };
        record[2] = hit(partial->first_hit_depth);
        record[3] = hit(partial->rim_depth);
        for (int s = 0; s < S; ++s) {
            std::copy_n(&partial->segment_rgba[s].pixels[pixel * 4], 4, record + 4 + 4 * s);
        }
        return true;
    };
    const auto fold = [&](const std::vector<const float*>& records,
                          const std::vector<float*>& replies, float* out) {
        std::vector<double> transmittance(static_cast<std::size_t>(S), 1.0);
        for (std::size_t r = 0; r < records.size(); ++r) {
            const float* block = records[r];
            replies[r][0] = static_cast<float>(transmittance[static_cast<int>(block[1])]);
            if (std::isinf(out[0])) out[0] = block[2];
            if (std::isinf(out[1])) out[1] = block[3];
            for (int s = 0; s < S; ++s) {
                const float* rgba = block + 4 + 4 * s;
                float* into = out + 2 + 4 * s;
                for (int c = 0; c < 3; ++c) {
                    into[c] = static_cast<float>(into[c] + transmittance[s] * rgba[c]);
                }
                transmittance[s] *= 1.0 - static_cast<double>(rgba[3]);
                into[3] = static_cast<float>(1.0 - transmittance[s]);
            }
        }
    };
    std::vector<float> identity(static_cast<std::size_t>(2 + 4 * S), 0.0f);
    identity[0] = identity[1] = kInf;
    const auto unpack = [&](std::int64_t begin, std::int64_t end, const float* values) {
        for (std::int64_t pixel = begin; pixel < end; ++pixel) {
            const float* in = values + (pixel - begin) * (2 + 4 * S);
            if (!frame.first_hit_depth.pixels.empty()) frame.first_hit_depth.pixels[pixel] = in[0];
            if (!frame.rim_depth.pixels.empty()) frame.rim_depth.pixels[pixel] = in[1];
            for (int s = 0; s < S && !frame.segment_rgba.empty(); ++s) {
                std::copy_n(in + 2 + 4 * s, 4, &frame.segment_rgba[s].pixels[pixel * 4]);
            }
        }
    };
    const std::vector<float> entry_fronts =
        exchanges.scan({2 + 2 + 4 * S, 1, 2 + 4 * S}, pack, fold, identity, {1.0f}, unpack);
    for (std::size_t p = 0; p < entry_fronts.size(); ++p) {
        fronts.pixels[p * kFrontChannels + 1] = entry_fronts[p];
    }
}

// 3. The front-most depth of each segment, at the root.
void composite_segment_depths(Exchanges& exchanges, const ProxyFrame* partial, int segments,
                              ProxyFrame& frame) {
    const int S = segments;
    const auto pack = [&](std::int64_t pixel, float* record) {
        if (!starts_record(partial, pixel, record)) return false;
        for (int s = 0; s < S; ++s) record[1 + s] = partial->segment_depth[s].pixels[pixel];
        return true;
    };
    const auto fold = [&](const std::vector<const float*>& records, const std::vector<float*>&,
                          float* out) {
        for (const float* block : records) {
            for (int s = 0; s < S; ++s) {
                if (std::isinf(out[s])) out[s] = block[1 + s];
            }
        }
    };
    const auto unpack = [&](std::int64_t begin, std::int64_t end, const float* values) {
        for (std::int64_t pixel = begin; pixel < end; ++pixel) {
            for (int s = 0; s < S; ++s) {
                frame.segment_depth[s].pixels[pixel] = values[(pixel - begin) * S + s];
            }
        }
    };
    exchanges.scan({1 + S, 0, S}, pack, fold, std::vector<float>(S, kInf), {}, unpack);
}

// The frame the root fills: the segment images, the first hit and the rim; attenuation comes
// composited.
ProxyFrame segment_frame(const Camera& camera, const ProxyRequest& request, int segments,
                         bool root) {
    ProxyFrame frame;
    frame.camera = camera;
    const auto image = [&](int channels) {
        Image made(camera.width(), camera.height(), channels);
        if (!root) made.pixels.clear();
        return made;
    };
    if (request.segment_rgba) frame.segment_rgba.assign(segments, image(4));
    if (request.segment_depth) frame.segment_depth.assign(segments, image(1));
    if (request.first_hit_depth) frame.first_hit_depth = image(1);
    if (request.rim_depth) frame.rim_depth = image(1);
    return frame;
}

}  // namespace

ProxyFrame composite_light_field_pass(Communicator& communicator, const Camera& camera,
                                      const ProxyRequest& asked, const BlockPass& march, int root,
                                      double* exchange_seconds) {
    validate(asked);
    // A block cannot stop early (it does not know the opacity in front of it), so it marches to
    // its end: a request that stops once its first hit is found gets the same first hit.
    ProxyRequest request = asked;
    request.march.early_termination_opacity = 1.0;
    const int segments = segment_count(request);
    Exchanges exchanges{communicator, static_cast<std::int64_t>(camera.width()) * camera.height(),
                        root, 0.0, nullptr};
    const bool at_root = communicator.rank() == root;
    ProxyFrame frame = segment_frame(camera, request, segments, at_root);

    // 1. Each block from T = 1: its transmittance and crossings, and the attenuation.
    ProxyRequest first = request;
    first.segment_depth = false;
    first.first_hit_depth = false;
    first.rim_depth = false;
    first.segment_rgba = true;  // the ray's transmittance is marched for the segments
    first.depth_layers = request.segments == SegmentRule::layers && !request.isovalues.empty();
    first.front = Image(camera.width(), camera.height(), kFrontChannels);
    for (std::size_t p = 0; p < first.front.pixels.size(); p += kFrontChannels) {
        const float none[kFrontChannels] = {1.0f, 1.0f, 0.0f, kNaN};
        std::copy(none, none + kFrontChannels, &first.front.pixels[p]);
    }
    std::optional<ProxyFrame> partial = exchanges.march(march, first);
    if (request.attenuation || request.mean_depth) {
        ProxyRequest accumulated = request;
        accumulated.depth_layers = false;
        const ProxyFrame shell = frame_shell(camera, 0.0, false, accumulated);
        std::optional<ProxyFrame> part = partial;
        if (part) part->depth_layers.clear();
        const auto start = SteadyClock::now();
        ProxyFrame composited;
        try {
            composited = composite_proxies(communicator, shell, part ? &*part : nullptr, root);
        } catch (...) {
            if (!exchanges.failure) exchanges.failure = std::current_exception();
        }
        exchanges.seconds += seconds_since(start);
        frame.intervals = request.intervals;
        frame.attenuation = std::move(composited.attenuation);
        frame.mean_depth = std::move(composited.mean_depth);
    }
    Image fronts = find_fronts(exchanges, partial ? &*partial : nullptr, camera,
                               first.depth_layers ? request.isovalues : std::vector<double>{});

    // 2. Again from the state in front: segment colours and the first hit.
    ProxyRequest second = request;
    second.attenuation = second.mean_depth = second.optical_depth = false;
    second.depth_layers = false;
    second.segment_depth = false;
    second.segment_rgba = true;  // composited for the entry segments' transmittance in front
    second.front = fronts;
    partial = exchanges.march(march, second);
    composite_segments(exchanges, partial ? &*partial : nullptr, request, segments, fronts, frame);

    // 3. With the entry segment's transmittance in front too: the segment depths.
    if (request.segment_depth) {
        ProxyRequest third = second;
        third.segment_rgba = third.first_hit_depth = third.rim_depth = false;
        third.segment_depth = true;
        third.front = std::move(fronts);
        partial = exchanges.march(march, third);
        composite_segment_depths(exchanges, partial ? &*partial : nullptr, segments, frame);
    }
    if (exchange_seconds != nullptr) *exchange_seconds += exchanges.seconds;
    if (exchanges.failure) std::rethrow_exception(exchanges.failure);
    return frame;
}

}  // namespace insitu
