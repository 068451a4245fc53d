#include "insitu/parallel/compositing.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/trigonometric.hpp>
#include <limits>

#include "device/kernel_constants.hpp"
#include "insitu/core/check.hpp"
#include "insitu/error.hpp"
#include "parallel/compositing_exchange.hpp"
#include "parallel/compositing_scratch.hpp"
#include "parallel/interleaving_fold.hpp"
#include "parallel/record_index.hpp"

namespace insitu {

namespace {

using detail::append;
using detail::fragments_in;
using detail::index_records;
using detail::load_record;
using detail::RecordIndex;
using detail::RecordRef;

constexpr float kInf = std::numeric_limits<float>::infinity();

// The fragment record's channels, as kernels/render/proxy_renderer.cl writes them.
enum FragmentChannel {
    kFirstIndex,
    kLastIndex,
    kFirstValue,
    kLastValue,
    kFirstDepth,
    kLastDepth,
    kFirstT,
    kLastT,
    kTransmittance,
    kFragmentChannels
};

// What one pixel's record holds: the fragment, then the pass's outputs in a fixed order. The
// folded (final) record is the same without the fragment.
struct ProxyLayout {
    int layers = 0;
    bool distortion = false;
    int intervals = 0;
    bool attenuation = false;
    bool mean_depth = false;
    bool optical_depth = false;
    bool entry_depth = false;  ///< per interval, the depth of the first sample that gave it light
    /// Folded: re-entries and their light (2); a block's record: interleaving_fold.hpp's.
    bool interleaving = false;
    float sin_tilt = 0.0f;
    std::vector<float> isovalues;

    int outputs() const {
        return layers * (distortion ? 2 : 1) +
               intervals * ((attenuation ? 1 : 0) + (mean_depth ? 1 : 0) + (optical_depth ? 1 : 0) +
                            (entry_depth ? 1 : 0)) +
               (interleaving ? 2 : 0);
    }
    int record() const {
        return kFragmentChannels + outputs() +
               (interleaving ? detail::kInterleavingHead + intervals - 2 : 0);
    }
};

ProxyLayout layout_of(const ProxyFrame& shell) {
    ProxyLayout layout;
    layout.layers = static_cast<int>(shell.depth_layers.size());
    layout.distortion = !shell.distortion_layers.empty();
    layout.attenuation = shell.attenuation.channels > 0;
    layout.mean_depth = shell.mean_depth.channels > 0;
    layout.optical_depth = shell.optical_depth.channels > 0;
    layout.entry_depth = shell.entry_depth.channels > 0;
    layout.interleaving = shell.interleaving.channels > 0;
    layout.intervals = shell.intervals ? shell.intervals->count() : 0;
    if ((layout.mean_depth || layout.entry_depth || layout.interleaving) && !layout.attenuation) {
        fail<InvalidArgument>(
            "compositing mean and entry depths and interleaving needs the attenuation they read");
    }
    layout.sin_tilt = static_cast<float>(std::sin(glm::radians(shell.distortion_tilt_deg)));
    layout.isovalues.assign(shell.isovalues.begin(), shell.isovalues.end());
    return layout;
}

// An image of that size whose pixels are not allocated yet: the shells of non-root ranks stay
// small, and the root allocates what it fills (allocate_images).
Image sized(int width, int height, int channels) {
    Image image;
    image.width = width;
    image.height = height;
    image.channels = channels;
    return image;
}

void allocate_images(ProxyFrame& frame) {
    for (std::vector<Image>* list : {&frame.depth_layers, &frame.distortion_layers}) {
        for (Image& image : *list) image.pixels.assign(image.pixel_count() * image.channels, 0.0f);
    }
    for (Image* image : {&frame.attenuation, &frame.mean_depth, &frame.optical_depth,
                         &frame.entry_depth, &frame.interleaving}) {
        image->pixels.assign(image->pixel_count() * image->channels, 0.0f);
    }
}

// This rank's records of the pixels in [begin, end) it has a fragment for: (pixel, record)*.
Bytes pack_proxy_records(const ProxyLayout& layout, const ProxyFrame& partial, std::int64_t begin,
                         std::int64_t end) {
    std::vector<float> record(static_cast<std::size_t>(layout.record()));
    Bytes bytes = detail::borrow_bytes();
    bytes.reserve(fragments_in(partial.fragment, kFragmentChannels, begin, end) *
                  (sizeof(std::uint32_t) + record.size() * sizeof(float)));
    const int I = layout.intervals;
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        const float* fragment = &partial.fragment.pixels[pixel * kFragmentChannels];
        if (fragment[kFirstIndex] < 0.0f) continue;
        std::copy(fragment, fragment + kFragmentChannels, record.begin());
        std::size_t next = kFragmentChannels;
        for (const Image& layer : partial.depth_layers) record[next++] = layer.pixels[pixel];
        for (const Image& layer : partial.distortion_layers) record[next++] = layer.pixels[pixel];
        for (const Image* image : {&partial.attenuation, &partial.mean_depth,
                                   &partial.optical_depth, &partial.entry_depth}) {
            if (image->pixels.empty()) continue;
            const float* channels = &image->pixels[pixel * I];
            std::copy(channels, channels + I, record.begin() + static_cast<std::ptrdiff_t>(next));
            next += static_cast<std::size_t>(I);
        }
        if (layout.interleaving) {
            const std::size_t size = detail::kInterleavingHead + static_cast<std::size_t>(I);
            const float* channels = &partial.interleaving.pixels[pixel * size];
            std::copy(channels, channels + size,
                      record.begin() + static_cast<std::ptrdiff_t>(next));
        }
        const auto index = static_cast<std::uint32_t>(pixel);
        append(bytes, &index, sizeof index);
        append(bytes, record.data(), record.size() * sizeof(float));
    }
    return bytes;
}

// The identity of the fold: what a pass over nothing gives (a ray that misses the grid).
void identity_outputs(const ProxyLayout& layout, float* out) {
    int next = 0;
    for (int l = 0; l < layout.layers * (layout.distortion ? 2 : 1); ++l) out[next++] = kInf;
    const int I = layout.intervals;
    if (layout.attenuation) {
        for (int j = 0; j < I; ++j) out[next++] = 0.0f;
    }
    if (layout.mean_depth) {
        for (int j = 0; j < I; ++j) out[next++] = kInf;
    }
    if (layout.optical_depth) {
        for (int j = 0; j < I; ++j) out[next++] = 0.0f;
    }
    if (layout.entry_depth) {
        for (int j = 0; j < I; ++j) out[next++] = kInf;
    }
    if (layout.interleaving) {
        out[next++] = 0.0f;
        out[next++] = 0.0f;
    }
}

// Scratch memory of a fold, allocated once per tile.
struct FoldScratch {
    std::vector<float> record;
    std::vector<double> weighted;
};

// Folds the fragments [first, last) of one pixel, front to back, into `out` (outputs()).
void fold_proxy_pixel(const ProxyLayout& layout, const RecordRef* first, const RecordRef* last,
                      FoldScratch& scratch, float* out) {
    const int L = layout.layers;
    const int I = layout.intervals;
    const int depth_at = 0;
    const int distortion_at = L;
    const int attenuation_at = L * (layout.distortion ? 2 : 1);
    const int mean_at = attenuation_at + (layout.attenuation ? I : 0);
    const int optical_at = mean_at + (layout.mean_depth ? I : 0);
    const int entry_at = optical_at + (layout.optical_depth ? I : 0);
    const int interleaving_at = entry_at + (layout.entry_depth ? I : 0);
    scratch.record.resize(static_cast<std::size_t>(layout.record()));
    float* const record = scratch.record.data();
    load_record(*first, layout.record(), record);
    const float* f = record;
    std::copy(f + kFragmentChannels, f + kFragmentChannels + layout.outputs(), out);
    // The mean depth is carried as attenuation-weighted depth until the end.
    std::vector<double>& weighted = scratch.weighted;
    weighted.assign(static_cast<std::size_t>(layout.mean_depth ? I : 0), 0.0);
    for (int j = 0; j < static_cast<int>(weighted.size()); ++j) {
        const float a = out[attenuation_at + j];
        weighted[j] = a > 0.0f ? static_cast<double>(a) * out[mean_at + j] : 0.0;
    }
    detail::InterleavingFold interleaving;
    if (layout.interleaving) interleaving.start(f + kFragmentChannels + interleaving_at);
    double transmittance = f[kTransmittance];
    float last_index = f[kLastIndex];
    float last_value = f[kLastValue];
    float last_depth = f[kLastDepth];
    float last_t = f[kLastT];
    for (const RecordRef* ref = first + 1; ref != last; ++ref) {
        load_record(*ref, layout.record(), record);
        const float* b = record;
        const float* b_out = b + kFragmentChannels;
        const bool adjacent = b[kFirstIndex] == last_index + 1.0f;
        for (int l = 0; l < L; ++l) {
            if (!std::isinf(out[depth_at + l])) continue;  // found in front
            const float iso = layout.isovalues[l];
            const float before = last_value;
            const float after = b[kFirstValue];
            if (adjacent && !std::isnan(before) && !std::isnan(after) &&
                ((before >= iso) != (after >= iso))) {
                // The pair the whole pass compares across the boundary, refined as it refines.
                const float fraction = (iso - before) / (after - before);
                out[depth_at + l] = last_depth + fraction * (b[kFirstDepth] - last_depth);
                if (layout.distortion) {
                    out[distortion_at + l] =
                        (last_t + fraction * (b[kFirstT] - last_t)) * layout.sin_tilt;
                }
            } else {
                out[depth_at + l] = b_out[depth_at + l];
                if (layout.distortion) out[distortion_at + l] = b_out[distortion_at + l];
            }
        }
        // The whole pass stops accumulating once 1 - T rounds to 1 in float (its early
        // termination at opacity 1): nothing behind a front that saturated counts.
        if (1.0f - static_cast<float>(transmittance) < 1.0f) {
            // Before the back's light joins the front's a_j: what its runs re-enter.
            if (layout.interleaving) {
                interleaving.add(b_out + interleaving_at, I, out + attenuation_at, transmittance);
            }
            for (int j = 0; j < I; ++j) {
                const float a_back = layout.attenuation ? b_out[attenuation_at + j] : 0.0f;
                if (layout.attenuation) {
                    out[attenuation_at + j] =
                        static_cast<float>(out[attenuation_at + j] + transmittance * a_back);
                }
                if (layout.mean_depth && a_back > 0.0f) {
                    weighted[j] += transmittance * a_back * b_out[mean_at + j];
                }
                if (layout.optical_depth) out[optical_at + j] += b_out[optical_at + j];
                // The entry depth of the front-most block that gave the interval light (one
                // that got light through what is in front: the whole pass's weight > 0).
                if (layout.entry_depth && std::isinf(out[entry_at + j]) &&
                    transmittance * a_back > 0.0) {
                    out[entry_at + j] = b_out[entry_at + j];
                }
            }
            transmittance *= b[kTransmittance];
        }
        last_index = b[kLastIndex];
        last_value = b[kLastValue];
        last_depth = b[kLastDepth];
        last_t = b[kLastT];
    }
    if (layout.mean_depth) {
        for (int j = 0; j < I; ++j) {
            const float a = out[attenuation_at + j];
            out[mean_at + j] = a > 0.0f ? static_cast<float>(weighted[j] / a) : kInf;
        }
    }
    if (layout.interleaving) {
        out[interleaving_at] = static_cast<float>(interleaving.reentries);
        out[interleaving_at + 1] = static_cast<float>(interleaving.reentered);
    }
}

// Folds the pixels [begin, end) from the records every rank sent: outputs() floats per pixel.
std::vector<float> fold_proxy_tile(const ProxyLayout& layout, const std::vector<Bytes>& messages,
                                   std::int64_t begin, std::int64_t end) {
    const int outputs = layout.outputs();
    std::vector<float> tile = detail::borrow_floats();
    tile.resize(static_cast<std::size_t>((end - begin) * outputs));
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        identity_outputs(layout, &tile[(pixel - begin) * outputs]);
    }
    RecordIndex& index = detail::reused_record_index();
    index_records(messages, layout.record(), begin, end, index);
    FoldScratch scratch;
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        const std::uint32_t first = index.starts[pixel - begin];
        const std::uint32_t last = index.starts[pixel - begin + 1];
        if (first == last) continue;
        fold_proxy_pixel(layout, index.refs.data() + first, index.refs.data() + last, scratch,
                         &tile[(pixel - begin) * outputs]);
    }
    return tile;
}

// Writes folded pixels [begin, begin + count) into the shell's images.
void unpack_proxy_outputs(const ProxyLayout& layout, const float* values, std::int64_t begin,
                          std::int64_t count, ProxyFrame& frame) {
    const int outputs = layout.outputs();
    const int I = layout.intervals;
    for (std::int64_t p = 0; p < count; ++p) {
        const float* in = values + p * outputs;
        const std::int64_t pixel = begin + p;
        int next = 0;
        for (Image& layer : frame.depth_layers) layer.pixels[pixel] = in[next++];
        for (Image& layer : frame.distortion_layers) layer.pixels[pixel] = in[next++];
        for (Image* image :
             {&frame.attenuation, &frame.mean_depth, &frame.optical_depth, &frame.entry_depth}) {
            if (image->pixels.empty()) continue;
            std::copy(in + next, in + next + I, &image->pixels[pixel * I]);
            next += I;
        }
        if (layout.interleaving)
            std::copy(in + next, in + next + 2, &frame.interleaving.pixels[pixel * 2]);
    }
}

void check_partial(const ProxyLayout& layout, const ProxyFrame& shell, const ProxyFrame& partial) {
    const std::size_t pixels =
        static_cast<std::size_t>(shell.camera.width()) * shell.camera.height();
    if (partial.fragment.pixels.size() != pixels * kFragmentChannels) {
        fail<InvalidArgument>("compositing: the partial frame has no fragment records for its ",
                              pixels, " pixels (was the volume given a region?)");
    }
    const auto same = [](const Image& a, const Image& b) {
        return a.width == b.width && a.height == b.height && a.channels == b.channels;
    };
    bool matches =
        static_cast<int>(partial.depth_layers.size()) == layout.layers &&
        partial.distortion_layers.size() == shell.distortion_layers.size() &&
        same(partial.attenuation, shell.attenuation) &&
        same(partial.mean_depth, shell.mean_depth) &&
        same(partial.optical_depth, shell.optical_depth) &&
        same(partial.entry_depth, shell.entry_depth) &&
        (layout.interleaving
             ? partial.interleaving.width == shell.interleaving.width &&
                   partial.interleaving.height == shell.interleaving.height &&
                   partial.interleaving.channels == detail::kInterleavingHead + layout.intervals
             : partial.interleaving.pixels.empty());
    for (std::size_t l = 0; matches && l < shell.depth_layers.size(); ++l) {
        matches = same(partial.depth_layers[l], shell.depth_layers[l]);
    }
    if (!matches) {
        fail<InvalidArgument>("compositing: the partial frame ", partial,
                              " does not hold the images of ", shell);
    }
}

// Ground truth: the fragment's first index, premultiplied RGBA, depth.
constexpr int kRenderingRecord = 6;
constexpr int kRenderingOutputs = 5;

Bytes pack_rendering_records(const Rendering& partial, std::int64_t begin, std::int64_t end) {
    Bytes bytes = detail::borrow_bytes();
    bytes.reserve(fragments_in(partial.fragment, 1, begin, end) *
                  (sizeof(std::uint32_t) + kRenderingRecord * sizeof(float)));
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        const float first = partial.fragment.pixels[pixel];
        if (first < 0.0f) continue;
        const float* rgba = &partial.rgba.pixels[pixel * 4];
        const float record[kRenderingRecord] = {first,   rgba[0], rgba[1],
                                                rgba[2], rgba[3], partial.depth.pixels[pixel]};
        const auto index = static_cast<std::uint32_t>(pixel);
        append(bytes, &index, sizeof index);
        append(bytes, record, sizeof record);
    }
    return bytes;
}

std::vector<float> fold_rendering_tile(const std::vector<Bytes>& messages, std::int64_t begin,
                                       std::int64_t end) {
    std::vector<float> tile = detail::borrow_floats();
    tile.assign(static_cast<std::size_t>((end - begin) * kRenderingOutputs), 0.0f);
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        tile[(pixel - begin) * kRenderingOutputs + 4] = kInf;
    }
    RecordIndex& index = detail::reused_record_index();
    index_records(messages, kRenderingRecord, begin, end, index);
    float v[kRenderingRecord];
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        const std::uint32_t first = index.starts[pixel - begin];
        const std::uint32_t last = index.starts[pixel - begin + 1];
        if (first == last) continue;
        double colour[3] = {0.0, 0.0, 0.0};
        double transmittance = 1.0;
        float depth = kInf;
        for (std::uint32_t r = first; r < last; ++r) {
            load_record(index.refs[r], kRenderingRecord, v);
            for (int c = 0; c < 3; ++c) colour[c] += transmittance * v[1 + c];
            transmittance *= 1.0 - static_cast<double>(v[4]);
            if (std::isinf(depth)) depth = v[5];
        }
        float* out = &tile[(pixel - begin) * kRenderingOutputs];
        for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(colour[c]);
        out[3] = static_cast<float>(1.0 - transmittance);
        out[4] = depth;
    }
    return tile;
}

// Writes folded pixels [begin, end) into a rendering's rgba and depth.
void unpack_rendering(const float* values, std::int64_t begin, std::int64_t end,
                      Rendering& result) {
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        const float* in = values + (pixel - begin) * kRenderingOutputs;
        std::copy(in, in + 4, &result.rgba.pixels[pixel * 4]);
        result.depth.pixels[pixel] = in[4];
    }
}

}  // namespace

ProxyFrame frame_shell(const Camera& camera, double tilt_deg, bool multi_perspective,
                       const ProxyRequest& request) {
    ProxyFrame frame;
    frame.multi_perspective = multi_perspective;
    frame.camera = camera;
    frame.distortion_tilt_deg = tilt_deg;
    const int width = camera.width();
    const int height = camera.height();
    const bool want_layers = request.depth_layers && !request.isovalues.empty();
    const bool accumulates = request.attenuation || request.mean_depth || request.optical_depth;
    if (want_layers) {
        frame.isovalues = request.isovalues;
        for (std::size_t l = 0; l < request.isovalues.size(); ++l) {
            frame.depth_layers.push_back(sized(width, height, 1));
            if (multi_perspective) frame.distortion_layers.push_back(sized(width, height, 1));
        }
    }
    if (accumulates) {
        if (!request.intervals) fail<InvalidArgument>("attenuation requested without intervals");
        frame.intervals = request.intervals;
        const int I = request.intervals->count();
        if (request.attenuation) frame.attenuation = sized(width, height, I);
        if (request.mean_depth) frame.mean_depth = sized(width, height, I);
        if (request.optical_depth) frame.optical_depth = sized(width, height, I);
        if (request.entry_depth) frame.entry_depth = sized(width, height, I);
        if (request.interleaving) frame.interleaving = sized(width, height, 2);
    }
    return frame;
}

ProxyFrame composite_proxies(Communicator& communicator, const ProxyFrame& shell,
                             const ProxyFrame* partial, int root, CompositingSchedule schedule,
                             int radix) {
    const ProxyLayout layout = layout_of(shell);
    if (partial != nullptr) check_partial(layout, shell, *partial);
    const std::int64_t pixels =
        static_cast<std::int64_t>(shell.camera.width()) * shell.camera.height();
    ProxyFrame frame = shell;
    if (communicator.rank() == root) allocate_images(frame);
    const std::size_t record_bytes =
        sizeof(std::uint32_t) + static_cast<std::size_t>(layout.record()) * sizeof(float);
    detail::composite_exchange(
        communicator, schedule, radix, pixels, layout.outputs(), root, record_bytes,
        [&](std::int64_t begin, std::int64_t end) {
            return partial != nullptr ? pack_proxy_records(layout, *partial, begin, end) : Bytes{};
        },
        [&](const std::vector<Bytes>& messages, std::int64_t begin, std::int64_t end) {
            return fold_proxy_tile(layout, messages, begin, end);
        },
        [&](std::int64_t begin, std::int64_t end, const float* values) {
            unpack_proxy_outputs(layout, values, begin, end - begin, frame);
        });
    return frame;
}

Rendering composite_rendering(Communicator& communicator, int width, int height,
                              const Rendering* partial, int root, CompositingSchedule schedule,
                              int radix) {
    const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
    if (partial != nullptr && partial->fragment.pixels.size() != static_cast<std::size_t>(pixels)) {
        fail<InvalidArgument>("compositing: the partial rendering has no fragment records for its ",
                              pixels, " pixels (was the volume given a region?)");
    }
    Rendering result;
    if (communicator.rank() == root) {
        result.rgba = Image(width, height, 4);
        result.depth = Image(width, height, 1);
    }
    detail::composite_exchange(
        communicator, schedule, radix, pixels, kRenderingOutputs, root,
        sizeof(std::uint32_t) + kRenderingRecord * sizeof(float),
        [&](std::int64_t begin, std::int64_t end) {
            return partial != nullptr ? pack_rendering_records(*partial, begin, end) : Bytes{};
        },
        [&](const std::vector<Bytes>& messages, std::int64_t begin, std::int64_t end) {
            return fold_rendering_tile(messages, begin, end);
        },
        [&](std::int64_t begin, std::int64_t end, const float* values) {
            unpack_rendering(values, begin, end, result);
        });
    return result;
}

ProxyFrame composite_proxies(const ProxyFrame& shell, const std::vector<ProxyFrame>& partials) {
    const ProxyLayout layout = layout_of(shell);
    const std::int64_t pixels =
        static_cast<std::int64_t>(shell.camera.width()) * shell.camera.height();
    std::vector<Bytes> messages;
    for (const ProxyFrame& partial : partials) {
        check_partial(layout, shell, partial);
        messages.push_back(pack_proxy_records(layout, partial, 0, pixels));
    }
    const std::vector<float> image = fold_proxy_tile(layout, messages, 0, pixels);
    ProxyFrame frame = shell;
    allocate_images(frame);
    unpack_proxy_outputs(layout, image.data(), 0, pixels, frame);
    return frame;
}

Rendering composite_rendering(int width, int height, const std::vector<Rendering>& partials) {
    const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
    std::vector<Bytes> messages;
    for (const Rendering& partial : partials) {
        if (partial.fragment.pixels.size() != static_cast<std::size_t>(pixels)) {
            fail<InvalidArgument>("compositing: a partial rendering has no fragment records");
        }
        messages.push_back(pack_rendering_records(partial, 0, pixels));
    }
    Rendering result;
    result.rgba = Image(width, height, 4);
    result.depth = Image(width, height, 1);
    unpack_rendering(fold_rendering_tile(messages, 0, pixels).data(), 0, pixels, result);
    return result;
}

}  // namespace insitu
