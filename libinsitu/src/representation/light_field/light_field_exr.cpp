// The light-field codec (light_field_exr.hpp). It works on bytes in memory as the view codec
// does (exr_frame.hpp, whose streams, header checks and channel reader it shares): the writer
// checksums what it encodes and stores it through the crash-safe path, and the reader parses
// only bytes it already checked against the manifest, and of those only the parts of the
// cameras it was asked for.
#include "representation/light_field/light_field_exr.hpp"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "archive/archive_format.hpp"
#include "archive/exr_frame.hpp"
#include "insitu/error.hpp"
#include "representation/light_field/light_field_attenuation_coding.hpp"
#include "representation/light_field/light_field_exr_checks.hpp"
#include "representation/light_field/light_field_subsampling.hpp"

namespace insitu::archive_format {

namespace {

/// RGBA and depth per segment, first-hit and rim depth, a_j and mean depth per interval.
constexpr long long kMaxCameraChannels = 5ll * kMaxLightFieldSegments + 2 + 2ll * kMaxIntervals;

/// The channel names of one camera's part, grouped as its images are.
struct CameraChannels {
    std::vector<std::string> rgba;           ///< 4 per segment
    std::vector<std::string> segment_depth;  ///< one per segment when there are several
    std::string depth;
    std::string rim;                       ///< empty without a rim threshold
    std::vector<std::string> attenuation;  ///< L
    std::vector<std::string> mean_depth;   ///< L

    /// Every name, in the order decode reads them (one pass over the part's chunks).
    std::vector<std::string> all() const {
        std::vector<std::string> names = rgba;
        names.insert(names.end(), segment_depth.begin(), segment_depth.end());
        names.push_back(depth);
        if (!rim.empty()) names.push_back(rim);
        names.insert(names.end(), attenuation.begin(), attenuation.end());
        names.insert(names.end(), mean_depth.begin(), mean_depth.end());
        return names;
    }
};

CameraChannels camera_channels(int camera, int segments, int intervals, bool rim) {
    const std::string part = camera_part(camera);
    CameraChannels names;
    for (int s = 0; s < segments; ++s) {
        // One segment is the whole ray: plain R, G, B, A, as any EXR viewer shows a layer.
        const std::string prefix = segments == 1 ? part : segment_prefix(part, s);
        for (const char* suffix : kRgbaChannels) names.rgba.push_back(prefix + suffix);
        if (segments > 1) names.segment_depth.push_back(prefix + kDepthChannel);
    }
    names.depth = part + kDepthChannel;
    if (rim) names.rim = part + kRimDepthChannel;
    for (int j = 0; j < intervals; ++j) {
        names.attenuation.push_back(interval_channel(part, kAttenuationChannel, j));
        names.mean_depth.push_back(interval_channel(part, kMeanDepthChannel, j));
    }
    return names;
}

Imf::PixelType depth_type(const LightFieldEncoding& encoding, int depth_bits) {
    return depth_bits == 16 ? Imf::HALF : encoding.depth_code_type;
}

std::string depth_encoding_text(int depth_bits, Imf::PixelType type) {
    if (depth_bits == 16) return "secant fraction (seed 001 Eq. 3) as HALF, +inf = no hit";
    return type == Imf::UINT ? "8-bit secant fraction: code round(f * 254) as UINT, 255 = no hit"
                             : "8-bit secant fraction: round(f * 254) / 254 as HALF, +inf = no hit";
}

/// Seed 001's 8-bit depth: the secant fraction in 254 steps, and a code of its own for "no hit".
int depth_code(float fraction) {
    if (fraction == std::numeric_limits<float>::infinity()) return kNoHitDepthCode;
    return static_cast<int>(std::lround(std::clamp(fraction, 0.0f, 1.0f) * kDepthCodeSteps));
}

// ---------------------------------------------------------------------------------------------
// Encoding

/// The attributes of every part (archive_format.hpp); the rig only on the first.
Imf::Header camera_header(const StepRecord& record, const LightFieldRecord& source,
                          const LightFieldImages& images, const LightFieldEncoding& encoding,
                          bool first) {
    const LightField& light_field = source.light_field;
    const int size = light_field.rig.map_size();
    const Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(size - 1, size - 1));
    Imf::Header header(window, window);
    header.setName(camera_part(images.camera));
    header.setType(Imf::SCANLINEIMAGE);
    header.compression() = encoding.compression;
    header.zipCompressionLevel() = kZipCompressionLevel;
    if (encoding.compression == Imf::DWAB_COMPRESSION) {
        header.dwaCompressionLevel() = encoding.dwa_level;
    }

    const int segments = light_field.segment_count();
    const int intervals = light_field.settings.attenuation ? light_field.intervals->count() : 0;
    const CameraChannels names = camera_channels(images.camera, segments, intervals,
                                                 light_field.settings.rim_threshold > 0.0);
    const Imf::PixelType depth = depth_type(encoding, light_field.settings.depth_bits);
    for (const std::string& name : names.rgba) header.channels().insert(name, encoding.compact);
    for (const std::string& name : names.segment_depth) header.channels().insert(name, depth);
    header.channels().insert(names.depth, depth);
    if (!names.rim.empty()) header.channels().insert(names.rim, depth);
    const int factor = light_field.settings.attenuation_subsampling;
    const int depth_factor = light_field.settings.stored_mean_depth_subsampling();
    for (const std::string& name : names.attenuation) {
        header.channels().insert(name, Imf::Channel(encoding.compact, factor, factor));
    }
    for (const std::string& name : names.mean_depth) {
        header.channels().insert(name, Imf::Channel(encoding.compact, depth_factor, depth_factor));
    }

    header.insert(kSchemaAttribute, Imf::IntAttribute(kArchiveSchemaVersion));
    // Steps are 64-bit; EXR has no 64-bit integer attribute, and a decimal string is exact.
    header.insert(kStepAttribute, Imf::StringAttribute(std::to_string(record.step)));
    header.insert(kTimeAttribute, Imf::DoubleAttribute(record.time));
    header.insert(kFieldAttribute, Imf::StringAttribute(source.field));
    header.insert(kLightFieldAttribute,
                  Imf::StringAttribute(light_field.settings.to_json().dump()));
    // JSON keeps doubles exact (shortest round-trip form).
    header.insert(kIsovaluesAttribute,
                  Imf::StringAttribute(nlohmann::json(light_field.isovalues).dump()));
    if (light_field.intervals) {
        header.insert(kIntervalsAttribute,
                      Imf::StringAttribute(light_field.intervals->to_json().dump()));
    }
    header.insert(kTransferFunctionAttribute,
                  Imf::StringAttribute(light_field.transfer_function.to_json().dump()));
    header.insert(kCameraIndexAttribute, Imf::IntAttribute(images.camera));
    header.insert(kCameraAttribute,
                  Imf::StringAttribute(light_field.rig.camera(images.camera).to_json().dump()));
    header.insert(kDepthEncodingAttribute, Imf::StringAttribute(depth_encoding_text(
                                               light_field.settings.depth_bits, depth)));
    if (first) {
        header.insert(kRigAttribute, Imf::StringAttribute(light_field.rig.to_json().dump()));
    }
    return header;
}

/// `value` as a channel of `type` holds it.
float stored_value(float value, Imf::PixelType type) {
    return type == Imf::HALF ? static_cast<float>(half(value)) : value;
}

/// The pixels of one part as OpenEXR takes them: FLOAT channels in place, HALF and UINT ones
/// converted (OpenEXR writes a slice only into a channel of its own type).
class PartPixels {
public:
    PartPixels(const LightFieldImages& images, const LightField& light_field,
               const LightFieldEncoding& encoding, const std::string& where)
        : size_(light_field.rig.map_size()) {
        const int segments = light_field.segment_count();
        const int intervals = light_field.settings.attenuation ? light_field.intervals->count() : 0;
        const CameraChannels names = camera_channels(images.camera, segments, intervals,
                                                     light_field.settings.rim_threshold > 0.0);
        halves_.reserve(names.all().size());
        codes_.reserve(names.all().size());
        for (int s = 0; s < segments; ++s) {
            for (int c = 0; c < 4; ++c) {
                add(names.rgba[4 * s + c], images.segment_rgba[s], c, encoding.compact);
            }
        }
        const int depth_bits = light_field.settings.depth_bits;
        const Imf::PixelType depth = depth_type(encoding, depth_bits);
        for (int s = 0; s < static_cast<int>(names.segment_depth.size()); ++s) {
            add_depth(names.segment_depth[s], images.segment_depth[s], depth_bits, depth, where);
        }
        add_depth(names.depth, images.depth, depth_bits, depth, where);
        if (!names.rim.empty()) add_depth(names.rim, images.rim_depth, depth_bits, depth, where);
        if (intervals == 0) return;
        const LightFieldSettings& settings = light_field.settings;
        const int factor = settings.attenuation_subsampling;
        const int depth_factor = settings.stored_mean_depth_subsampling();
        const bool coded = factor == 1 && (settings.codes_attenuation() || depth_factor > 1);
        if (factor > 1) {
            subsampled_ = subsample_attenuation(images.attenuation, images.mean_depth, factor);
        } else if (coded) {
            // Shares of the opacity the reader will see: the colour's alpha as stored.
            std::vector<Image> alphas = images.segment_rgba;
            for (Image& rgba : alphas) {
                for (float& value : rgba.pixels) value = stored_value(value, encoding.compact);
            }
            coded_ = encode_attenuation(
                images.attenuation, images.mean_depth, whole_ray_alpha(alphas),
                settings.codes_attenuation() ? settings.attenuation_bits : 0, depth_factor);
        }
        const Image& attenuation = factor > 1 ? subsampled_.attenuation
                                   : coded    ? coded_.attenuation
                                              : images.attenuation;
        const Image& mean_depth = factor > 1 ? subsampled_.mean_depth
                                  : coded    ? coded_.mean_depth
                                             : images.mean_depth;
        for (int j = 0; j < intervals; ++j) {
            add(names.attenuation[j], attenuation, j, encoding.compact, factor);
            add(names.mean_depth[j], mean_depth, j, encoding.compact, depth_factor);
        }
    }
    const Imf::FrameBuffer& frame_buffer() const { return frame_buffer_; }

private:
    /// Channel `channel` of `image`, which holds every `sampling`-th pixel of the part per side.
    void add(const std::string& name, const Image& image, int channel, Imf::PixelType type,
             int sampling = 1) {
        if (type == Imf::HALF) {
            std::vector<half>& plane = halves_.emplace_back(image.pixel_count());
            for (std::size_t i = 0; i < plane.size(); ++i) {
                plane[i] = half(image.pixels[i * image.channels + channel]);
            }
            insert_half(name, plane, image.width, sampling);
            return;
        }
        const std::size_t x_stride = sizeof(float) * image.channels;
        char* base = reinterpret_cast<char*>(const_cast<float*>(image.pixels.data()) + channel);
        frame_buffer_.insert(name, Imf::Slice(Imf::FLOAT, base, x_stride, x_stride * image.width,
                                              sampling, sampling));
    }

    void add_depth(const std::string& name, const Image& image, int depth_bits, Imf::PixelType type,
                   const std::string& where) {
        for (std::size_t i = 0; i < image.pixels.size(); ++i) {
            const float fraction = image.pixels[i];
            if (std::isnan(fraction) || fraction == -std::numeric_limits<float>::infinity()) {
                fail<InvalidArgument>(where, ": channel \"", name, "\" pixel ", i, " is ", fraction,
                                      " (a secant fraction, +inf for no hit)");
            }
        }
        if (depth_bits == 16) {
            add(name, image, 0, Imf::HALF);
            return;
        }
        if (type == Imf::UINT) {
            std::vector<std::uint32_t>& plane = codes_.emplace_back(image.pixel_count());
            for (std::size_t i = 0; i < plane.size(); ++i) {
                plane[i] = static_cast<std::uint32_t>(depth_code(image.pixels[i]));
            }
            frame_buffer_.insert(name,
                                 Imf::Slice(Imf::UINT, reinterpret_cast<char*>(plane.data()),
                                            sizeof(std::uint32_t), sizeof(std::uint32_t) * size_));
            return;
        }
        std::vector<half>& plane = halves_.emplace_back(image.pixel_count());
        for (std::size_t i = 0; i < plane.size(); ++i) {
            const int code = depth_code(image.pixels[i]);
            plane[i] = code == kNoHitDepthCode ? half(std::numeric_limits<float>::infinity())
                                               : half(static_cast<float>(code) / kDepthCodeSteps);
        }
        insert_half(name, plane, size_, 1);
    }

    void insert_half(const std::string& name, std::vector<half>& plane, int width, int sampling) {
        frame_buffer_.insert(
            name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(plane.data()), sizeof(half),
                             sizeof(half) * width, sampling, sampling));
    }

    int size_;
    // Reserved up front: slices point into these planes.
    std::vector<std::vector<half>> halves_;
    std::vector<std::vector<std::uint32_t>> codes_;
    SubsampledAttenuation subsampled_;
    CodedAttenuation coded_;
    Imf::FrameBuffer frame_buffer_;
};

// ---------------------------------------------------------------------------------------------
// Decoding

template <typename Value>
Value json_value(const Imf::Header& header, const char* name, const PartContext& where,
                 Value (*parse)(const nlohmann::json&)) {
    const nlohmann::json json = json_attribute(header, name, where);
    try {
        return parse(json);
    } catch (const std::exception& error) {
        where.error(std::string("attribute \"") + name + "\": " + error.what());
    }
}

/// What the whole light field shares, from the first part's header.
void read_light_field_attributes(const Imf::Header& header, LightField& light_field,
                                 const PartContext& where) {
    const auto* schema = header.findTypedAttribute<Imf::IntAttribute>(kSchemaAttribute);
    if (!schema) where.error(std::string("no int attribute \"") + kSchemaAttribute + "\"");
    if (schema->value() != kArchiveSchemaVersion) {
        where.error("schema version " + std::to_string(schema->value()) +
                    " (this libinsitu reads " + std::to_string(kArchiveSchemaVersion) + ")");
    }
    light_field.settings = json_value<LightFieldSettings>(
        header, kLightFieldAttribute, where, [](const nlohmann::json& json) {
            std::vector<std::string> unknown;
            LightFieldSettings settings = LightFieldSettings::from_json(json, &unknown);
            if (!unknown.empty()) fail<ParseError>("unknown key \"", unknown.front(), "\"");
            // Written before each was a default (light_field.hpp): no rims, lossless colour,
            // attenuation maps as captured.
            if (!json.contains("rim_threshold")) settings.rim_threshold = 0.0;
            if (!json.contains("colour_dwa_level")) settings.colour_dwa_level = 0.0;
            if (!json.contains("attenuation_bits")) settings.attenuation_bits = 0;
            if (!json.contains("mean_depth_subsampling")) settings.mean_depth_subsampling = 1;
            settings.validate();
            return settings;
        });
    light_field.rig = json_value<LightFieldRig>(
        header, kRigAttribute, where,
        [](const nlohmann::json& json) { return LightFieldRig::from_json(json); });
    if (light_field.rig.camera_count() != light_field.settings.cameras ||
        light_field.rig.map_size() != light_field.settings.size) {
        where.error("the rig has " + std::to_string(light_field.rig.camera_count()) +
                    " cameras of " + std::to_string(light_field.rig.map_size()) +
                    "^2, attribute \"" + kLightFieldAttribute + "\" says " +
                    std::to_string(light_field.settings.cameras) + " of " +
                    std::to_string(light_field.settings.size) + "^2");
    }
    light_field.isovalues = json_value<std::vector<double>>(
        header, kIsovaluesAttribute, where,
        [](const nlohmann::json& json) { return json.get<std::vector<double>>(); });
    if (header.findTypedAttribute<Imf::StringAttribute>(kIntervalsAttribute)) {
        light_field.intervals = json_value<IntervalSet>(
            header, kIntervalsAttribute, where, [](const nlohmann::json& json) {
                return IntervalSet(json.at("edges").get<std::vector<double>>());
            });
    }
    if (light_field.settings.attenuation && !light_field.intervals) {
        where.error(std::string("\"attenuation\" is set but there is no attribute \"") +
                    kIntervalsAttribute + "\"");
    }
    light_field.transfer_function = json_value<TransferFunction>(
        header, kTransferFunctionAttribute, where,
        [](const nlohmann::json& json) { return TransferFunction::from_json(json); });
    const int segments = light_field.segment_count();
    if (segments > kMaxLightFieldSegments) {
        where.error(std::to_string(segments) + " segments (at most " +
                    std::to_string(kMaxLightFieldSegments) + ")");
    }
}

/// The secant fractions of depth channels read as floats: codes or HALF code / 254 back to
/// fractions for 8-bit depth (the type says which), HALF fractions as they are for 16-bit.
void decode_depth(Image& depth, const Imf::Channel& channel, int depth_bits,
                  const std::string& name, const PartContext& where) {
    const auto refuse = [&](const std::string& what) {
        where.error("channel \"" + name + "\": " + what);
    };
    if (depth_bits == 16) {
        if (channel.type != Imf::HALF) refuse("16-bit depth is not HALF");
        return;
    }
    if (channel.type != Imf::UINT && channel.type != Imf::HALF) {
        refuse("8-bit depth is neither UINT codes nor HALF");
    }
    const float no_hit = std::numeric_limits<float>::infinity();
    for (float& value : depth.pixels) {
        const float code = channel.type == Imf::UINT ? value : value * kDepthCodeSteps;
        if (channel.type == Imf::HALF && value == no_hit) continue;
        const float rounded = std::round(code);
        // HALF holds code / 254 within 2^-12 relative, a quarter of a code at most.
        if (!(rounded >= 0.0f && rounded <= kNoHitDepthCode && std::abs(code - rounded) < 0.25f) ||
            (channel.type == Imf::HALF && rounded == kNoHitDepthCode)) {
            refuse("value " + std::to_string(value) + " is not an 8-bit depth code");
        }
        value = rounded == kNoHitDepthCode ? no_hit : rounded / kDepthCodeSteps;
    }
}

/// A lossy (DWA) part's colour back into what premultiplied colour is, 0 <= R, G, B <= A: the
/// DCT leaves errors of a fraction of a code either way, which where alpha is 0 would add light
/// to a transparent ray.
void restore_premultiplied(Image& rgba) {
    for (std::size_t p = 0; p < rgba.pixel_count(); ++p) {
        float* pixel = &rgba.pixels[4 * p];
        // min/max, not std::clamp: a damaged file may hold alpha < 0 or NaN.
        for (int c = 0; c < 3; ++c) pixel[c] = std::min(std::max(pixel[c], 0.0f), pixel[3]);
    }
}

bool lossy_colour(const Imf::Header& header) {
    return header.compression() == Imf::DWAA_COMPRESSION ||
           header.compression() == Imf::DWAB_COMPRESSION;
}

LightFieldImages read_camera(Imf::InputPart& part, int camera, const LightField& light_field,
                             const PartContext& where) {
    const int segments = light_field.segment_count();
    const int intervals = light_field.settings.attenuation ? light_field.intervals->count() : 0;
    const CameraChannels names =
        camera_channels(camera, segments, intervals, light_field.settings.rim_threshold > 0.0);
    // Attenuation maps subsampled by the settings' factor are read in a pass of their own, as
    // are mean depth maps subsampled alone.
    const LightFieldSettings& settings = light_field.settings;
    const int factor = settings.attenuation_subsampling;
    const int depth_factor = settings.stored_mean_depth_subsampling();
    const bool coded = factor == 1 && (settings.codes_attenuation() || depth_factor > 1);
    std::vector<std::string> all_names = names.all();
    std::vector<std::string> subsampled;
    if (factor > 1) subsampled = names.attenuation;
    if (depth_factor > 1) {
        subsampled.insert(subsampled.end(), names.mean_depth.begin(), names.mean_depth.end());
    }
    all_names.resize(all_names.size() - subsampled.size());
    const Imf::ChannelList& channels = part.header().channels();
    for (const std::string& name : names.all()) {
        const Imf::Channel* channel = channels.findChannel(name);
        if (!channel) where.error("no channel \"" + name + "\"");
        const bool is_subsampled =
            std::find(subsampled.begin(), subsampled.end(), name) != subsampled.end();
        const int expected = is_subsampled ? depth_factor : 1;
        if (channel->xSampling != expected || channel->ySampling != expected) {
            where.error("channel \"" + name + "\" is subsampled by " +
                        std::to_string(channel->xSampling) + "x" +
                        std::to_string(channel->ySampling) + ", the settings say " +
                        std::to_string(expected));
        }
    }
    const Image all = read_channels(part, all_names, where);
    const int size = light_field.rig.map_size();
    if (all.width != size || all.height != size) {
        where.error("data window " + std::to_string(all.width) + "x" + std::to_string(all.height) +
                    ", the rig's maps are " + std::to_string(size) + "x" + std::to_string(size));
    }
    LightFieldImages images;
    images.camera = camera;
    int first = 0;
    for (int s = 0; s < segments; ++s, first += 4) {
        images.segment_rgba.push_back(channel_range(all, first, 4));
        if (lossy_colour(part.header())) restore_premultiplied(images.segment_rgba.back());
    }
    const int depth_bits = light_field.settings.depth_bits;
    for (const std::string& name : names.segment_depth) {
        Image& depth = images.segment_depth.emplace_back(channel_range(all, first++, 1));
        decode_depth(depth, *channels.findChannel(name), depth_bits, name, where);
    }
    images.depth = channel_range(all, first++, 1);
    decode_depth(images.depth, *channels.findChannel(names.depth), depth_bits, names.depth, where);
    if (!names.rim.empty()) {
        images.rim_depth = channel_range(all, first++, 1);
        decode_depth(images.rim_depth, *channels.findChannel(names.rim), depth_bits, names.rim,
                     where);
    }
    if (intervals > 0 && factor == 1 && !coded) {
        images.attenuation = channel_range(all, first, intervals);
        images.mean_depth = channel_range(all, first + intervals, intervals);
    } else if (intervals > 0 && factor == 1) {
        const Image depth = depth_factor > 1
                                ? read_subsampled_channels(part, subsampled, depth_factor, where)
                                : channel_range(all, first + intervals, intervals);
        decode_attenuation({channel_range(all, first, intervals), depth},
                           whole_ray_alpha(images.segment_rgba), settings.codes_attenuation(),
                           images.attenuation, images.mean_depth);
    } else if (intervals > 0) {
        const Image stored = read_subsampled_channels(part, subsampled, factor, where);
        upsample_attenuation(
            {channel_range(stored, 0, intervals), channel_range(stored, intervals, intervals)},
            whole_ray_alpha(images.segment_rgba), images.attenuation, images.mean_depth);
    }
    return images;
}

}  // namespace

EncodedLightField encode_light_field(const StepRecord& record, const LightFieldRecord& source,
                                     const LightFieldEncoding& archive_encoding,
                                     const std::string& relative_path) {
    const std::string where = "step " + std::to_string(record.step) + " light field of \"" +
                              source.field + "\" (" + relative_path + ")";
    const LightField& light_field = source.light_field;
    check_light_field(light_field, where);
    const LightFieldEncoding encoding =
        with_colour_dwa_level(archive_encoding, light_field.settings.colour_dwa_level);

    // Parts in camera order, whatever order the capture listed them in.
    std::vector<const LightFieldImages*> cameras;
    for (const LightFieldImages& images : light_field.cameras) cameras.push_back(&images);
    std::sort(cameras.begin(), cameras.end(),
              [](const auto* a, const auto* b) { return a->camera < b->camera; });
    EncodedLightField encoded;
    std::vector<Imf::Header> headers;
    for (const LightFieldImages* images : cameras) {
        headers.push_back(camera_header(record, source, *images, encoding, headers.empty()));
        encoded.cameras.push_back(images->camera);
    }

    MemoryOutputStream stream(relative_path);
    std::string current_part;
    try {
        // No OpenEXR worker threads, as for the views (exr_frame_encoder.cpp): the encoding stays
        // on the writer thread and its lowered priority.
        Imf::MultiPartOutputFile file(stream, headers.data(), static_cast<int>(headers.size()),
                                      /*overrideSharedAttributes=*/false, /*numThreads=*/0);
        for (std::size_t p = 0; p < cameras.size(); ++p) {
            current_part = camera_part(cameras[p]->camera);
            const PartPixels pixels(*cameras[p], light_field, encoding, where);
            Imf::OutputPart part(file, static_cast<int>(p));
            part.setFrameBuffer(pixels.frame_buffer());
            part.writePixels(light_field.rig.map_size());
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& error) {
        fail<IoError>("cannot encode EXR \"", relative_path, "\" part \"", current_part,
                      "\": ", error.what());
    }
    encoded.bytes = std::move(stream.bytes());
    return encoded;
}

LightField decode_light_field(const std::vector<char>& bytes, const std::string& path,
                              const std::vector<int>& cameras, int map_size) {
    LightField light_field;
    PartContext where{path, "(header)"};
    try {
        check_headers(bytes, path, [map_size](const std::string&) {
            return PartLimits{map_size, map_size, kMaxCameraChannels,
                              "the light field's map size in the manifest"};
        });
        MemoryInputStream stream(bytes, path);
        // No reconstruction of a damaged chunk offset table: damage is an error here.
        Imf::MultiPartInputFile file(stream, Imf::globalThreadCount(), false);
        const Imf::Header& first = file.header(0);
        where.part = first.hasName() ? first.name() : "(part 0)";
        read_light_field_attributes(first, light_field, where);
        if (light_field.rig.map_size() != map_size) {
            where.error("maps of " + std::to_string(light_field.rig.map_size()) +
                        "^2, the manifest records " + std::to_string(map_size) + "^2");
        }
        const int camera_count = light_field.rig.camera_count();
        for (const int camera : cameras) {
            if (camera < 0 || camera >= camera_count) {
                fail<InvalidArgument>("\"", path, "\": camera ", camera, " is outside the rig (",
                                      camera_count, " cameras, 0..", camera_count - 1, ")");
            }
        }
        std::map<int, int> part_of_camera;
        for (int p = 0; p < file.parts(); ++p) {
            const Imf::Header& header = file.header(p);
            where.part = header.hasName() ? header.name() : "(part " + std::to_string(p) + ")";
            const auto* index = header.findTypedAttribute<Imf::IntAttribute>(kCameraIndexAttribute);
            if (!index)
                where.error(std::string("no int attribute \"") + kCameraIndexAttribute + "\"");
            const int camera = index->value();
            if (camera < 0 || camera >= camera_count || where.part != camera_part(camera) ||
                !part_of_camera.emplace(camera, p).second) {
                where.error("camera " + std::to_string(camera) +
                            " is outside the rig, repeated, or not this part's camera");
            }
        }
        std::set<int> wanted(cameras.begin(), cameras.end());
        if (cameras.empty()) {
            for (const auto& [camera, part] : part_of_camera) wanted.insert(camera);
        }
        for (const int camera : wanted) {
            const auto found = part_of_camera.find(camera);
            if (found == part_of_camera.end()) continue;  // the caller sees which it lacks
            where.part = camera_part(camera);
            Imf::InputPart part(file, found->second);
            light_field.cameras.push_back(read_camera(part, camera, light_field, where));
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& error) {
        where.error(error.what());
    }
    return light_field;
}

}  // namespace insitu::archive_format
