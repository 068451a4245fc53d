// The EXR frame codec's decoding side (exr_frame.hpp), and the part readers the light-field
// codec shares. The reader parses only bytes it already checked against the manifest, and every
// header against the view's size (exr_header_guard.cpp) before OpenEXR allocates anything.
// OpenEXR reports damage with Iex exceptions; each becomes an IoError naming the file and the
// part.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>

#include "archive/archive_format.hpp"
#include "archive/exr_frame.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

const std::string& string_attribute(const Imf::Header& header, const char* name,
                                    const PartContext& where) {
    const auto* attribute = header.findTypedAttribute<Imf::StringAttribute>(name);
    if (!attribute) where.error(std::string("no string attribute \"") + name + "\"");
    return attribute->value();
}

nlohmann::json json_attribute(const Imf::Header& header, const char* name,
                              const PartContext& where) {
    try {
        return nlohmann::json::parse(string_attribute(header, name, where));
    } catch (const nlohmann::json::exception& error) {
        where.error(std::string("attribute \"") + name + "\" is not valid JSON: " + error.what());
    }
}

/// Reads the channels `names` of one part into one image (channel c = names[c]).
Image read_channels(Imf::InputPart& part, const std::vector<std::string>& names,
                    const PartContext& where) {
    const Imath::Box2i window = part.header().dataWindow();
    const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
    // A header that passed the checksum can still be foreign; refuse absurd sizes before
    // allocating (2^28 pixels = 16384^2).
    if (width < 1 || height < 1 || width * height > (1ll << 28)) {
        where.error("data window " + std::to_string(width) + "x" + std::to_string(height) +
                    " is empty or too large");
    }
    Image image(static_cast<int>(width), static_cast<int>(height), static_cast<int>(names.size()));
    Imf::FrameBuffer frame_buffer;
    const std::size_t x_stride = sizeof(float) * image.channels;
    const std::size_t y_stride = x_stride * image.width;
    for (int c = 0; c < image.channels; ++c) {
        // HALF channels convert to float on read. The base is shifted so that data-window
        // coordinates index the zero-based buffer.
        char* base = reinterpret_cast<char*>(image.pixels.data() + c) -
                     static_cast<std::ptrdiff_t>(window.min.x * x_stride + window.min.y * y_stride);
        frame_buffer.insert(names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    }
    part.setFrameBuffer(frame_buffer);
    part.readPixels(window.min.y, window.max.y);
    return image;
}

/// Splits an interleaved image into consecutive groups of `count` channels.
Image channel_range(const Image& all, int first, int count) {
    Image image(all.width, all.height, count);
    for (std::size_t p = 0; p < all.pixel_count(); ++p) {
        for (int c = 0; c < count; ++c) {
            image.pixels[p * count + c] = all.pixels[p * all.channels + first + c];
        }
    }
    return image;
}

namespace {

/// The frame-level metadata every part of a frame carries.
void read_frame_attributes(const Imf::Header& header, ProxyFrame& frame, const PartContext& where) {
    const auto* schema = header.findTypedAttribute<Imf::IntAttribute>(kSchemaAttribute);
    if (!schema) where.error(std::string("no int attribute \"") + kSchemaAttribute + "\"");
    if (schema->value() != kArchiveSchemaVersion) {
        where.error("schema version " + std::to_string(schema->value()) +
                    " (this libinsitu reads " + std::to_string(kArchiveSchemaVersion) + ")");
    }
    const nlohmann::json camera = json_attribute(header, kCameraAttribute, where);
    try {
        frame.camera = Camera::from_json(camera);
    } catch (const std::exception& error) {
        where.error("attribute \"" + std::string(kCameraAttribute) + "\": " + error.what());
    }
    if (frame.multi_perspective) {
        const auto* tilt = header.findTypedAttribute<Imf::DoubleAttribute>(kTiltAttribute);
        if (!tilt) where.error(std::string("no double attribute \"") + kTiltAttribute + "\"");
        frame.distortion_tilt_deg = tilt->value();
    }
    try {
        frame.isovalues =
            json_attribute(header, kIsovaluesAttribute, where).get<std::vector<double>>();
        if (header.findTypedAttribute<Imf::StringAttribute>(kIntervalsAttribute)) {
            const nlohmann::json intervals = json_attribute(header, kIntervalsAttribute, where);
            frame.intervals = IntervalSet(intervals.at("edges").get<std::vector<double>>());
        }
    } catch (const IoError&) {
        throw;
    } catch (const std::exception& error) {
        where.error(std::string("isovalues or intervals attribute: ") + error.what());
    }
}

/// How many channels name_of(0), name_of(1), ... the part has, in a row.
template <typename NameOf>
int count_channels(const Imf::ChannelList& channels, NameOf name_of) {
    int count = 0;
    while (count < 1024 && channels.findChannel(name_of(count))) ++count;
    return count;
}

template <typename NameOf>
std::vector<std::string> names_of(int count, NameOf name_of) {
    std::vector<std::string> names;
    for (int i = 0; i < count; ++i) names.push_back(name_of(i));
    return names;
}

/// One single-channel image per layer channel of a "depth"/"distortion" part.
std::vector<Image> read_layers(Imf::InputPart& part, const PartContext& where) {
    auto name_of = [&](int k) { return layer_channel(where.part, k); };
    const int count = count_channels(part.header().channels(), name_of);
    if (count == 0) where.error("no channel \"" + name_of(0) + "\"");
    const Image all = read_channels(part, names_of(count, name_of), where);
    std::vector<Image> layers(static_cast<std::size_t>(count), Image(all.width, all.height, 1));
    for (std::size_t p = 0; p < all.pixel_count(); ++p) {
        for (int k = 0; k < count; ++k) layers[k].pixels[p] = all.pixels[p * count + k];
    }
    return layers;
}

/// a_j, and z-mean, tau and z-entry when present, of an "attenuation" part.
void read_attenuation(Imf::InputPart& part, ProxyFrame& frame, const PartContext& where) {
    const Imf::ChannelList& channels = part.header().channels();
    constexpr int kKinds = 4;
    const char* suffixes[kKinds] = {kAttenuationChannel, kMeanDepthChannel, kOpticalDepthChannel,
                                    kEntryDepthChannel};
    Image* targets[kKinds] = {&frame.attenuation, &frame.mean_depth, &frame.optical_depth,
                              &frame.entry_depth};
    int counts[kKinds];
    std::vector<std::string> names;
    for (int i = 0; i < kKinds; ++i) {
        auto name_of = [&](int j) { return interval_channel(where.part, suffixes[i], j); };
        counts[i] = count_channels(channels, name_of);
        for (int j = 0; j < counts[i]; ++j) names.push_back(name_of(j));
    }
    const int intervals = std::max({counts[0], counts[1], counts[2], counts[3]});
    for (int i = 0; i < kKinds; ++i) {
        if (counts[i] != 0 && counts[i] != intervals) {
            where.error("channels \"" + where.part + suffixes[i] +
                        "..\": " + std::to_string(counts[i]) + " intervals, expected " +
                        std::to_string(intervals));
        }
    }
    if (intervals == 0) {
        where.error("no channel \"" + interval_channel(where.part, suffixes[0], 0) + "\"");
    }
    const std::string reentries = where.part + kReentriesChannel;
    const std::string reentered = where.part + kReenteredChannel;
    const bool has_interleaving = channels.findChannel(reentries) != nullptr;
    if (has_interleaving) {
        if (!channels.findChannel(reentered)) where.error("\"" + reentered + "\" missing");
        names.push_back(reentries);
        names.push_back(reentered);
    }
    const Image all = read_channels(part, names, where);
    int first = 0;
    for (int i = 0; i < kKinds; ++i) {
        if (counts[i] == 0) continue;
        *targets[i] = channel_range(all, first, counts[i]);
        first += counts[i];
    }
    if (has_interleaving) frame.interleaving = channel_range(all, first, 2);
}

/// An RGBA part: a training rendering or the stored one.
Image read_rgba(Imf::InputPart& part, const PartContext& where) {
    std::vector<std::string> names;
    for (const char* suffix : kRgbaChannels) {
        names.push_back(where.part + suffix);
        if (!part.header().channels().findChannel(names.back())) {
            where.error("no channel \"" + names.back() + "\"");
        }
    }
    return read_channels(part, names, where);
}

/// The colour model of a "model" part: its table image, checked against L and K.
ColourModel read_model(Imf::InputPart& part, const PartContext& where) {
    const Imf::Header& header = part.header();
    const auto* intervals = header.findTypedAttribute<Imf::IntAttribute>(kModelIntervalsAttribute);
    const auto* clusters = header.findTypedAttribute<Imf::IntAttribute>(kModelClustersAttribute);
    if (!intervals || !clusters) {
        where.error(std::string("no int attributes \"") + kModelIntervalsAttribute + "\" and \"" +
                    kModelClustersAttribute + "\"");
    }
    const std::string channel = where.part + kModelChannel;
    if (!header.channels().findChannel(channel)) where.error("no channel \"" + channel + "\"");
    const Image table = read_channels(part, {channel}, where);
    const long long row = 4ll * intervals->value() + 3;
    if (table.width != row || table.height != clusters->value()) {
        where.error("table is " + std::to_string(table.width) + "x" + std::to_string(table.height) +
                    ", expected (4 L + 3) x K = " + std::to_string(row) + "x" +
                    std::to_string(clusters->value()));
    }
    try {
        return ColourModel::from_table(intervals->value(), clusters->value(), table.pixels);
    } catch (const InvalidArgument& error) {
        where.error(error.what());
    }
}

}  // namespace

ProxyFrame decode_frame(const std::vector<char>& bytes, const std::string& path,
                        const std::vector<std::string>& parts, bool multi_perspective,
                        const FrameLimits& limits) {
    ProxyFrame frame;
    frame.multi_perspective = multi_perspective;
    PartContext where{path, "(header)"};
    try {
        check_headers(bytes, path, [&limits](const std::string& part) {
            // The model is a (4 L + 3) x K table (archive_format.hpp); every other part is an
            // image of the view, with at most attenuation, mean, optical and entry depth (four
            // channels per interval) and the two interleaving channels.
            constexpr long long kMaxChannels = 4ll * kMaxIntervals + 2;
            if (part == kModelPart) {
                return PartLimits{4ll * kMaxIntervals + 3, kMaxColourModelClusters, kMaxChannels,
                                  "the largest model"};
            }
            return PartLimits{limits.max_width, limits.max_height, kMaxChannels, "the view"};
        });
        MemoryInputStream stream(bytes, path);
        // No reconstruction of a damaged chunk offset table: damage is an error here.
        Imf::MultiPartInputFile file(stream, Imf::globalThreadCount(), false);
        std::map<std::string, int> part_index;
        for (int p = 0; p < file.parts(); ++p) {
            if (file.header(p).hasName()) part_index[file.header(p).name()] = p;
        }
        bool first = true;
        for (const std::string& name : parts) {
            where.part = name;
            const auto found_part = part_index.find(name);
            if (found_part == part_index.end()) where.error("missing from the file");
            Imf::InputPart part(file, found_part->second);
            if (first) read_frame_attributes(part.header(), frame, where);
            first = false;
            const std::string base =
                multi_perspective ? name.substr(std::strlen(kMultiPrefix)) : name;
            if (base == kDepthPart) {
                frame.depth_layers = read_layers(part, where);
            } else if (base == kDistortionPart) {
                frame.distortion_layers = read_layers(part, where);
            } else if (base == kAttenuationPart) {
                read_attenuation(part, frame, where);
            } else if (base.rfind(kTrainingPartPrefix, 0) == 0 &&
                       base == kTrainingPartPrefix + std::to_string(frame.training.size())) {
                frame.training.push_back(read_rgba(part, where));
            } else if (base == kRenderingPart && !multi_perspective &&
                       frame.rendering.pixels.empty()) {
                frame.rendering = read_rgba(part, where);
            } else if (base == kModelPart && !frame.colour_model) {
                frame.colour_model = read_model(part, where);
            } else {
                where.error("unknown or out-of-order part");
            }
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& error) {
        where.error(error.what());
    }
    return frame;
}

}  // namespace insitu::archive_format
