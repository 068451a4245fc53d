// The EXR frame codec (exr_frame.hpp). Both directions work on bytes in memory: the writer
// checksums what it encodes and stores it through the crash-safe path (errors such as EFBIG or
// ENOSPC come back with errno), and the reader parses only bytes it already checked against the
// manifest. OpenEXR reports damage with Iex exceptions; each becomes an IoError naming the file
// and the part.
#include "archive/exr_frame.hpp"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVersion.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "archive/archive_format.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

// ---------------------------------------------------------------------------------------------
// Encoding

Imf::Compression parse_compression(const std::string& name) {
    if (name == "none") return Imf::NO_COMPRESSION;
    if (name == "rle") return Imf::RLE_COMPRESSION;
    if (name == "zips") return Imf::ZIPS_COMPRESSION;
    if (name == "zip") return Imf::ZIP_COMPRESSION;
    if (name == "piz") return Imf::PIZ_COMPRESSION;
    if (name == "pxr24") return Imf::PXR24_COMPRESSION;
    if (name == "b44") return Imf::B44_COMPRESSION;
    fail<InvalidArgument>("compression \"", name,
                          "\" (expected none, rle, zips, zip, piz, pxr24 or b44)");
}

namespace {

/// One channel of an EXR part: channel `channel` of `image`.
struct ChannelSource {
    std::string name;
    const Image* image = nullptr;
    int channel = 0;
    Imf::PixelType type = Imf::FLOAT;
};

struct PartSource {
    std::string name;
    std::vector<ChannelSource> channels;
    nlohmann::json training_function;    ///< train<k> parts only
    const ColourModel* model = nullptr;  ///< model parts only
    /// Pixels made for the part (the model's table as an image); shared so that channel
    /// pointers stay valid when the part is moved.
    std::shared_ptr<const Image> storage{};
};

void add_channels(PartSource& part, const Image& image, const char* suffix, Imf::PixelType type) {
    for (int c = 0; c < image.channels; ++c) {
        part.channels.push_back({interval_channel(part.name, suffix, c), &image, c, type});
    }
}

/// Checks that every image of a part has the same size; `what` names them for the message.
void check_same_size(const PartSource& part, const std::string& where) {
    const Image* first = part.channels.front().image;
    for (const ChannelSource& channel : part.channels) {
        if (channel.image->width != first->width || channel.image->height != first->height) {
            fail<InvalidArgument>(where, ": part \"", part.name, "\": channel \"", channel.name,
                                  "\" is ", channel.image->width, "x", channel.image->height,
                                  ", not ", first->width, "x", first->height);
        }
    }
}

/// The parts of one frame, in file order; empty images make no part.
std::vector<PartSource> frame_parts(const ProxyFrame& frame, const ViewRecord& view,
                                    StoragePrecision precision, const std::string& where) {
    // Depth and distortion are world distances of up to a few hundred voxels; half's 11-bit
    // mantissa would round them by up to ~0.1 voxel at 256 voxels, visible as terracing in
    // relighting and re-projection, so they are always FLOAT. The attenuation family and the
    // training images are fractions and colours where half's 1e-3 relative error is invisible.
    const Imf::PixelType compact = precision == StoragePrecision::half ? Imf::HALF : Imf::FLOAT;
    const bool multi = frame.multi_perspective;
    std::vector<PartSource> parts;

    auto layers_part = [&](const char* base, const std::vector<Image>& layers) {
        if (layers.empty()) return;
        PartSource part{part_name(base, multi), {}, {}};
        for (std::size_t k = 0; k < layers.size(); ++k) {
            if (layers[k].channels != 1 || layers[k].pixels.empty()) {
                fail<InvalidArgument>(where, ": ", part.name, " layer ", k, " has ",
                                      layers[k].channels, " channels and ", layers[k].pixel_count(),
                                      " pixels (expected 1 channel)");
            }
            part.channels.push_back(
                {layer_channel(part.name, static_cast<int>(k)), &layers[k], 0, Imf::FLOAT});
        }
        parts.push_back(std::move(part));
    };
    layers_part(kDepthPart, frame.depth_layers);
    if (multi) layers_part(kDistortionPart, frame.distortion_layers);

    PartSource attenuation{part_name(kAttenuationPart, multi), {}, {}};
    // The entry depth orders intervals as the mean depth does, so it is stored as compactly.
    const Image* interval_images[4] = {&frame.attenuation, &frame.mean_depth, &frame.optical_depth,
                                       &frame.entry_depth};
    const char* interval_suffixes[4] = {kAttenuationChannel, kMeanDepthChannel,
                                        kOpticalDepthChannel, kEntryDepthChannel};
    int interval_count = -1;
    for (int i = 0; i < 4; ++i) {
        const Image& image = *interval_images[i];
        if (image.pixels.empty()) continue;
        if (interval_count >= 0 && image.channels != interval_count) {
            fail<InvalidArgument>(where, ": ", attenuation.name, interval_suffixes[i], ": ",
                                  image.channels, " intervals, not ", interval_count);
        }
        if (image.channels > kMaxIntervals) {
            fail<InvalidArgument>(where, ": ", attenuation.name, ": ", image.channels,
                                  " intervals (at most ", kMaxIntervals, ")");
        }
        interval_count = image.channels;
        add_channels(attenuation, image, interval_suffixes[i], compact);
    }
    if (!frame.interleaving.pixels.empty()) {
        // Beside the intervals it describes: a count (HALF holds integers to 2048 exactly) and
        // an attenuation.
        if (frame.interleaving.channels != 2 || attenuation.channels.empty()) {
            fail<InvalidArgument>(where, ": interleaving has ", frame.interleaving.channels,
                                  " channels",
                                  attenuation.channels.empty() ? " and no attenuation" : "",
                                  " (expected 2 beside the attenuation proxies)");
        }
        attenuation.channels.push_back(
            {attenuation.name + kReentriesChannel, &frame.interleaving, 0, compact});
        attenuation.channels.push_back(
            {attenuation.name + kReenteredChannel, &frame.interleaving, 1, compact});
    }
    if (!attenuation.channels.empty()) parts.push_back(std::move(attenuation));

    for (std::size_t t = 0; t < frame.training.size(); ++t) {
        const Image& image = frame.training[t];
        const std::string name = kTrainingPartPrefix + std::to_string(t);
        if (image.channels != 4 || image.pixels.empty()) {
            fail<InvalidArgument>(where, ": training image ", t, " has ", image.channels,
                                  " channels and ", image.pixel_count(), " pixels (expected RGBA)");
        }
        PartSource part{name, {}, nullptr};
        for (int c = 0; c < 4; ++c) {
            part.channels.push_back({name + kTrainingChannels[c], &image, c, compact});
        }
        if (t < view.training_transfer_functions.size()) {
            part.training_function = view.training_transfer_functions[t].to_json();
        }
        parts.push_back(std::move(part));
    }
    if (!frame.rendering.pixels.empty()) {
        if (frame.rendering.channels != 4 || multi) {
            fail<InvalidArgument>(where, ": the stored rendering has ", frame.rendering.channels,
                                  " channels (expected RGBA, single perspective only)");
        }
        PartSource part{kRenderingPart, {}, nullptr};
        for (int c = 0; c < 4; ++c) {
            part.channels.push_back(
                {std::string(kRenderingPart) + kRgbaChannels[c], &frame.rendering, c, compact});
        }
        parts.push_back(std::move(part));
    }
    if (frame.colour_model) {
        const ColourModel& model = *frame.colour_model;
        if (interval_count >= 0 && model.intervals() != interval_count) {
            fail<InvalidArgument>(where, ": colour model has ", model.intervals(),
                                  " intervals, the attenuation proxies ", interval_count);
        }
        auto table = std::make_shared<Image>(model.row_floats(), model.clusters(), 1);
        table->pixels = model.table();
        PartSource part{part_name(kModelPart, multi), {}, {}, &model, table};
        part.channels.push_back({part.name + kModelChannel, table.get(), 0, Imf::FLOAT});
        parts.push_back(std::move(part));
    }
    for (const PartSource& part : parts) check_same_size(part, where);
    return parts;
}

/// The frame-level attributes, on every part of that frame so that each part describes itself.
void add_frame_attributes(Imf::Header& header, const StepRecord& record, const ViewRecord& view,
                          const ProxyFrame& frame) {
    header.insert(kSchemaAttribute, Imf::IntAttribute(kArchiveSchemaVersion));
    // Steps are 64-bit; EXR has no 64-bit integer attribute, and a decimal string is exact.
    header.insert(kStepAttribute, Imf::StringAttribute(std::to_string(record.step)));
    header.insert(kTimeAttribute, Imf::DoubleAttribute(record.time));
    header.insert(kFieldAttribute,
                  Imf::StringAttribute(view.field.empty() ? record.field : view.field));
    header.insert(kViewAttribute, Imf::IntAttribute(view.view_index));
    header.insert(kViewConfigAttribute, Imf::StringAttribute(view.view.to_json().dump()));
    header.insert(kPerspectiveAttribute,
                  Imf::StringAttribute(frame.multi_perspective ? "multi" : "single"));
    header.insert(kCameraAttribute, Imf::StringAttribute(frame.camera.to_json().dump()));
    if (frame.multi_perspective) {
        header.insert(kTiltAttribute, Imf::DoubleAttribute(frame.distortion_tilt_deg));
    }
    // JSON keeps doubles exact (shortest round-trip form); a FloatVectorAttribute would not.
    header.insert(kIsovaluesAttribute,
                  Imf::StringAttribute(nlohmann::json(frame.isovalues).dump()));
    if (frame.intervals) {
        header.insert(kIntervalsAttribute, Imf::StringAttribute(frame.intervals->to_json().dump()));
    }
    header.insert(kTransferFunctionAttribute,
                  Imf::StringAttribute(view.transfer_function.to_json().dump()));
    nlohmann::json training = nlohmann::json::array();
    for (const TransferFunction& tf : view.training_transfer_functions) {
        training.push_back(tf.to_json());
    }
    header.insert(kTrainingFunctionsAttribute, Imf::StringAttribute(training.dump()));
}

/// Encodes the multi-part EXR of one view; returns its bytes and the part names in file order.
std::string encode_parts(const StepRecord& record, const ViewRecord& view,
                         StoragePrecision precision, Imf::Compression compression,
                         const std::string& relative_path, std::vector<std::string>& part_names) {
    const std::string where = "step " + std::to_string(record.step) + " view " +
                              std::to_string(view.view_index) + " (" + relative_path + ")";
    struct FramedPart {
        const ProxyFrame* frame;
        PartSource source;
    };
    std::vector<FramedPart> parts;
    for (const std::optional<ProxyFrame>* frame : {&view.single, &view.multi}) {
        if (!frame->has_value()) continue;
        if ((*frame)->multi_perspective != (frame == &view.multi)) {
            fail<InvalidArgument>(where, ": the ", frame == &view.multi ? "multi" : "single",
                                  " frame has multi_perspective = ", (*frame)->multi_perspective);
        }
        for (PartSource& part : frame_parts(**frame, view, precision, where)) {
            parts.push_back({&**frame, std::move(part)});
        }
    }
    if (parts.empty()) fail<InvalidArgument>(where, ": no proxy images to store");

    // Multi-part files must share one display window; the union of the parts' sizes holds each
    // part's data window (all parts of a view normally have the view's size).
    int display_width = 1, display_height = 1;
    for (const FramedPart& part : parts) {
        display_width = std::max(display_width, part.source.channels.front().image->width);
        display_height = std::max(display_height, part.source.channels.front().image->height);
    }
    const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(display_width - 1, display_height - 1));

    std::vector<Imf::Header> headers;
    part_names.clear();
    for (const FramedPart& part : parts) {
        const Image& image = *part.source.channels.front().image;
        const Imath::Box2i data(Imath::V2i(0, 0), Imath::V2i(image.width - 1, image.height - 1));
        Imf::Header header(display, data);
        header.setName(part.source.name);
        header.setType(Imf::SCANLINEIMAGE);
        header.compression() = compression;
        header.zipCompressionLevel() = kZipCompressionLevel;
        for (const ChannelSource& channel : part.source.channels) {
            header.channels().insert(channel.name, Imf::Channel(channel.type));
        }
        add_frame_attributes(header, record, view, *part.frame);
        if (!part.source.training_function.is_null()) {
            header.insert(kTrainingFunctionAttribute,
                          Imf::StringAttribute(part.source.training_function.dump()));
        }
        if (part.source.model) {
            header.insert(kModelIntervalsAttribute,
                          Imf::IntAttribute(part.source.model->intervals()));
            header.insert(kModelClustersAttribute,
                          Imf::IntAttribute(part.source.model->clusters()));
            header.insert(kModelLayoutAttribute, Imf::StringAttribute(kModelLayout));
            nlohmann::json functions = nlohmann::json::array();
            for (const TransferFunction& tf : view.training_transfer_functions) {
                functions.push_back(tf.to_json());
            }
            header.insert(kModelFunctionsAttribute, Imf::StringAttribute(functions.dump()));
        }
        headers.push_back(std::move(header));
        part_names.push_back(part.source.name);
    }

    MemoryOutputStream stream(relative_path);
    std::string current_part;
    try {
        // No OpenEXR worker threads: the encoding stays on the calling (writer) thread and its
        // lowered priority, where the global pool, should the host have sized one with
        // Imf::setGlobalThreadCount, runs at its creator's priority on the simulation's cores.
        Imf::MultiPartOutputFile file(stream, headers.data(), static_cast<int>(headers.size()),
                                      /*overrideSharedAttributes=*/false, /*numThreads=*/0);
        for (std::size_t p = 0; p < parts.size(); ++p) {
            current_part = parts[p].source.name;
            Imf::FrameBuffer frame_buffer;
            // OpenEXR writes a slice only into a channel of its own type, so HALF channels get
            // a converted copy (round to nearest); FLOAT channels are read in place.
            std::vector<std::vector<half>> halves;
            halves.reserve(parts[p].source.channels.size());
            for (const ChannelSource& channel : parts[p].source.channels) {
                const Image& image = *channel.image;
                if (channel.type == Imf::HALF) {
                    std::vector<half>& plane = halves.emplace_back(image.pixel_count());
                    for (std::size_t i = 0; i < plane.size(); ++i) {
                        plane[i] = half(image.pixels[i * image.channels + channel.channel]);
                    }
                    frame_buffer.insert(channel.name,
                                        Imf::Slice(Imf::HALF, reinterpret_cast<char*>(plane.data()),
                                                   sizeof(half), sizeof(half) * image.width));
                    continue;
                }
                const std::size_t x_stride = sizeof(float) * image.channels;
                char* base = reinterpret_cast<char*>(const_cast<float*>(image.pixels.data()) +
                                                     channel.channel);
                frame_buffer.insert(channel.name,
                                    Imf::Slice(Imf::FLOAT, base, x_stride, x_stride * image.width));
            }
            Imf::OutputPart part(file, static_cast<int>(p));
            part.setFrameBuffer(frame_buffer);
            part.writePixels(parts[p].source.channels.front().image->height);
        }
    } catch (const std::exception& error) {
        fail<IoError>("cannot encode EXR \"", relative_path, "\" part \"", current_part,
                      "\": ", error.what());
    }
    return std::move(stream.bytes());
}

// ---------------------------------------------------------------------------------------------
// Decoding

}  // namespace

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

void check_compression(const std::string& name) {
    parse_compression(name);
}

bool holds_proxy_images(const ViewRecord& view) {
    for (const std::optional<ProxyFrame>* frame : {&view.single, &view.multi}) {
        if (frame->has_value() &&
            !frame_parts(**frame, view, StoragePrecision::single, "view").empty()) {
            return true;
        }
    }
    return false;
}

EncodedView encode_view(const StepRecord& record, const ViewRecord& view,
                        StoragePrecision precision, const std::string& compression,
                        const std::string& relative_path) {
    EncodedView encoded;
    encoded.bytes = encode_parts(record, view, precision, parse_compression(compression),
                                 relative_path, encoded.parts);
    return encoded;
}

namespace {

/// Checks that OpenEXR will read exactly `size` bytes for this attribute, so its parse stays in
/// step with skip_header's walk: a channel list is read entry by entry up to its terminating
/// null, not by its declared size (a fuzzed list shorter than its entries made OpenEXR read the
/// next bytes as attributes, one of them a 1.8 GB string). Types libinsitu never writes are
/// refused, since each has a reader of its own with sizes inside its value.
void check_attribute_value(const std::vector<char>& bytes, std::size_t at, std::size_t name_end,
                           std::size_t type_end, std::size_t value, std::size_t size,
                           const PartContext& where) {
    const std::string name(&bytes[at], name_end - at);
    const std::string type(&bytes[name_end + 1], type_end - name_end - 1);
    static const std::map<std::string, std::size_t> fixed_sizes = {
        {"int", 4}, {"float", 4},       {"double", 8},   {"box2i", 16},
        {"v2f", 8}, {"compression", 1}, {"lineOrder", 1}};
    const auto fixed = fixed_sizes.find(type);
    if (fixed != fixed_sizes.end()) {
        if (size != fixed->second) {
            where.error("attribute \"" + name + "\" of type " + type + " declares " +
                        std::to_string(size) + " bytes (it has " + std::to_string(fixed->second) +
                        ")");
        }
        return;
    }
    if (type == "string") return;  // read as exactly `size` bytes
    if (type != "chlist") {
        where.error("attribute \"" + name + "\" has type \"" + type +
                    "\", which libinsitu archives do not hold");
    }
    // Entries: name\0, then pixel type (int32), pLinear + 3 reserved bytes, x and y sampling
    // (int32 each); a null byte ends the list.
    const std::size_t end = value + size;
    std::size_t entry = value;
    for (;;) {
        const auto terminator = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(entry),
                                          bytes.begin() + static_cast<std::ptrdiff_t>(end), '\0');
        const auto stop = static_cast<std::size_t>(terminator - bytes.begin());
        if (stop == end) break;
        if (stop == entry) {
            if (entry + 1 == end) return;  // the list's null byte is its last byte
            break;
        }
        entry = stop + 1 + 16;
        if (entry > end) break;
    }
    where.error("attribute \"" + name + "\": channel list does not fill its " +
                std::to_string(size) + " bytes exactly");
}

/// Walks the attribute list of one header from `at` without allocating anything: each attribute
/// is name\0 type\0 int32 size value[size], and a size past the end of the file is refused here
/// (OpenEXR would allocate it first). Returns where the header ends; an empty header (the
/// multi-part terminator) ends right after its null byte.
std::size_t skip_header(const std::vector<char>& bytes, std::size_t at, const PartContext& where) {
    const auto name_end = [&](std::size_t from) {
        // OpenEXR names are at most 255 bytes (31 in older files).
        const std::size_t limit = std::min(bytes.size(), from + 256);
        const auto end = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(from),
                                   bytes.begin() + static_cast<std::ptrdiff_t>(limit), '\0');
        if (end == bytes.begin() + static_cast<std::ptrdiff_t>(limit)) {
            where.error("attribute name or type at byte " + std::to_string(from) +
                        " is unterminated");
        }
        return static_cast<std::size_t>(end - bytes.begin());
    };
    for (;;) {
        if (at >= bytes.size()) where.error("header runs past the end of the file");
        const std::size_t name = name_end(at);
        if (name == at) return at + 1;  // the empty name that ends the header
        const std::size_t type = name_end(name + 1);
        if (bytes.size() - (type + 1) < 4) where.error("header runs past the end of the file");
        std::int32_t size = 0;
        for (int b = 3; b >= 0; --b) {  // little-endian, as every EXR integer
            size = static_cast<std::int32_t>(static_cast<std::uint32_t>(size) << 8 |
                                             static_cast<unsigned char>(bytes[type + 1 + b]));
        }
        const std::size_t value = type + 5;
        if (size < 0 || static_cast<std::size_t>(size) > bytes.size() - value) {
            where.error("attribute \"" + std::string(&bytes[at], name - at) + "\" declares " +
                        std::to_string(size) + " bytes, past the end of the file (" +
                        std::to_string(bytes.size()) + " bytes)");
        }
        check_attribute_value(bytes, at, name, type, value, static_cast<std::size_t>(size), where);
        at = value + static_cast<std::size_t>(size);
    }
}

}  // namespace

void check_headers(const std::vector<char>& bytes, const std::string& path,
                   const std::function<PartLimits(const std::string& part)>& limits_of) {
    PartContext where{path, "(header)"};
    if (bytes.size() < 8) where.error("too short for an OpenEXR file");
    std::int32_t magic = 0;
    std::int32_t version = 0;
    std::memcpy(&magic, bytes.data(), 4);  // little-endian hosts only, as the rest of libinsitu
    std::memcpy(&version, bytes.data() + 4, 4);
    if (magic != Imf::MAGIC) where.error("not an OpenEXR file (bad magic number)");
    const bool multi_part = Imf::isMultiPart(version);
    std::size_t at = 8;
    for (int index = 0;; ++index) {
        where.part = "(header)";
        const std::size_t end = skip_header(bytes, at, where);
        if (end == at + 1) {
            if (multi_part && index > 0) break;
            where.error("empty header");
        }
        // Every attribute size is now known to fit the file: parsing allocates at most that.
        MemoryInputStream stream(bytes, path);
        stream.seekg(at);
        Imf::Header header;
        header.readFrom(stream, version);
        if (header.hasName()) where.part = header.name();
        if (header.hasType() && header.type() != Imf::SCANLINEIMAGE) {
            where.error("part type \"" + header.type() + "\" (libinsitu writes scan lines)");
        }
        const Imath::Box2i window = header.dataWindow();
        const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
        const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
        const PartLimits limits = limits_of(header.hasName() ? header.name() : std::string());
        if (width < 1 || height < 1 || width > limits.max_width || height > limits.max_height) {
            where.error("data window " + std::to_string(width) + "x" + std::to_string(height) +
                        " is empty or larger than " + std::to_string(limits.max_width) + "x" +
                        std::to_string(limits.max_height) + " (" + limits.bound + ")");
        }
        long long channels = 0;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) ++channels;
        if (channels > limits.max_channels) {
            where.error(std::to_string(channels) + " channels (a libinsitu part of this kind " +
                        "has at most " + std::to_string(limits.max_channels) + ")");
        }
        // The chunk offset table (8 bytes a chunk, at least one chunk per 256 lines for every
        // compression) is in the file, so the file bounds it.
        if ((height + 255) / 256 * 8 > static_cast<long long>(bytes.size())) {
            where.error("data window height " + std::to_string(height) +
                        " needs a chunk table larger than the file (" +
                        std::to_string(bytes.size()) + " bytes)");
        }
        at = end;
        if (!multi_part) break;
    }
}

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
