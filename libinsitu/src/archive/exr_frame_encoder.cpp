// The EXR frame codec's encoding side (exr_frame.hpp): the proxies of one view become the parts
// of one multi-part OpenEXR file in memory, which the writer checksums and stores through the
// crash-safe path (errors such as EFBIG or ENOSPC come back with errno). What cannot be stored
// is an InvalidArgument before OpenEXR sees it; an OpenEXR failure is an IoError naming the file
// and the part.
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "archive/archive_format.hpp"
#include "archive/exr_frame.hpp"
#include "insitu/error.hpp"

namespace insitu::archive_format {

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

/// The "depth" or "distortion" part (`base`): one FLOAT channel per layer; no layers, no part.
void add_layers_part(std::vector<PartSource>& parts, const char* base, bool multi,
                     const std::vector<Image>& layers, const std::string& where) {
    if (layers.empty()) return;
    PartSource part{part_name(base, multi), {}, {}};
    for (std::size_t k = 0; k < layers.size(); ++k) {
        if (layers[k].channels != 1 || layers[k].pixels.empty()) {
            fail<InvalidArgument>(where, ": ", part.name, " layer ", k, " has ", layers[k].channels,
                                  " channels and ", layers[k].pixel_count(),
                                  " pixels (expected 1 channel)");
        }
        part.channels.push_back(
            {layer_channel(part.name, static_cast<int>(k)), &layers[k], 0, Imf::FLOAT});
    }
    parts.push_back(std::move(part));
}

/// The "attenuation" part: the per-interval images the frame holds and its interleaving, if
/// any. Returns their interval count (-1: no per-interval image).
int add_attenuation_part(std::vector<PartSource>& parts, const ProxyFrame& frame,
                         Imf::PixelType compact, const std::string& where) {
    PartSource attenuation{part_name(kAttenuationPart, frame.multi_perspective), {}, {}};
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
    return interval_count;
}

/// One RGBA part per training image, each with the transfer function it was rendered with.
void add_training_parts(std::vector<PartSource>& parts, const ProxyFrame& frame,
                        const ViewRecord& view, Imf::PixelType compact, const std::string& where) {
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
}

/// The stored rendering's RGBA part (single perspective only), when the frame holds one.
void add_rendering_part(std::vector<PartSource>& parts, const ProxyFrame& frame,
                        Imf::PixelType compact, const std::string& where) {
    if (frame.rendering.pixels.empty()) return;
    if (frame.rendering.channels != 4 || frame.multi_perspective) {
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

/// The colour model's part, its table as a one-channel image, when the frame holds a model;
/// `interval_count` is the attenuation part's (-1: none), which the model must match.
void add_model_part(std::vector<PartSource>& parts, const ProxyFrame& frame, int interval_count,
                    const std::string& where) {
    if (!frame.colour_model) return;
    const ColourModel& model = *frame.colour_model;
    if (interval_count >= 0 && model.intervals() != interval_count) {
        fail<InvalidArgument>(where, ": colour model has ", model.intervals(),
                              " intervals, the attenuation proxies ", interval_count);
    }
    auto table = std::make_shared<Image>(model.row_floats(), model.clusters(), 1);
    table->pixels = model.table();
    PartSource part{part_name(kModelPart, frame.multi_perspective), {}, {}, &model, table};
    part.channels.push_back({part.name + kModelChannel, table.get(), 0, Imf::FLOAT});
    parts.push_back(std::move(part));
}

/// The parts of one frame, in file order; empty images make no part.
std::vector<PartSource> frame_parts(const ProxyFrame& frame, const ViewRecord& view,
                                    StoragePrecision precision, const std::string& where) {
    // Depth and distortion are world distances of up to a few hundred voxels; half's 11-bit
    // mantissa would round them by up to ~0.1 voxel at 256 voxels, visible as terracing in
    // relighting and re-projection, so they are always FLOAT. The attenuation family and the
    // training images are fractions and colours where half's 1e-3 relative error is invisible.
    const Imf::PixelType compact = precision == StoragePrecision::half ? Imf::HALF : Imf::FLOAT;
    std::vector<PartSource> parts;
    add_layers_part(parts, kDepthPart, frame.multi_perspective, frame.depth_layers, where);
    if (frame.multi_perspective) {
        add_layers_part(parts, kDistortionPart, true, frame.distortion_layers, where);
    }
    const int interval_count = add_attenuation_part(parts, frame, compact, where);
    add_training_parts(parts, frame, view, compact, where);
    add_rendering_part(parts, frame, compact, where);
    add_model_part(parts, frame, interval_count, where);
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

/// A part and the frame it belongs to (whose attributes its header carries).
struct FramedPart {
    const ProxyFrame* frame;
    PartSource source;
};

/// The parts of the view's single and multi frames, in file order.
std::vector<FramedPart> view_parts(const ViewRecord& view, StoragePrecision precision,
                                   const std::string& where) {
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
    return parts;
}

/// The display window the parts of one file share: multi-part files must share one, and the
/// union of the parts' sizes holds each part's data window (all parts of a view normally have
/// the view's size).
Imath::Box2i display_window(const std::vector<FramedPart>& parts) {
    int display_width = 1, display_height = 1;
    for (const FramedPart& part : parts) {
        display_width = std::max(display_width, part.source.channels.front().image->width);
        display_height = std::max(display_height, part.source.channels.front().image->height);
    }
    return Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(display_width - 1, display_height - 1));
}

/// The header of one part: its channels, its frame's attributes and its own.
Imf::Header part_header(const FramedPart& part, const Imath::Box2i& display,
                        Imf::Compression compression, const StepRecord& record,
                        const ViewRecord& view) {
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
        header.insert(kModelIntervalsAttribute, Imf::IntAttribute(part.source.model->intervals()));
        header.insert(kModelClustersAttribute, Imf::IntAttribute(part.source.model->clusters()));
        header.insert(kModelLayoutAttribute, Imf::StringAttribute(kModelLayout));
        nlohmann::json functions = nlohmann::json::array();
        for (const TransferFunction& tf : view.training_transfer_functions) {
            functions.push_back(tf.to_json());
        }
        header.insert(kModelFunctionsAttribute, Imf::StringAttribute(functions.dump()));
    }
    return header;
}

/// Writes the pixels of part `index` of `file` from its sources.
void write_part_pixels(Imf::MultiPartOutputFile& file, int index, const PartSource& source) {
    Imf::FrameBuffer frame_buffer;
    // OpenEXR writes a slice only into a channel of its own type, so HALF channels get a
    // converted copy (round to nearest); FLOAT channels are read in place.
    std::vector<std::vector<half>> halves;
    halves.reserve(source.channels.size());
    for (const ChannelSource& channel : source.channels) {
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
        char* base =
            reinterpret_cast<char*>(const_cast<float*>(image.pixels.data()) + channel.channel);
        frame_buffer.insert(channel.name,
                            Imf::Slice(Imf::FLOAT, base, x_stride, x_stride * image.width));
    }
    Imf::OutputPart part(file, index);
    part.setFrameBuffer(frame_buffer);
    part.writePixels(source.channels.front().image->height);
}

/// Encodes the multi-part EXR of one view; returns its bytes and the part names in file order.
std::string encode_parts(const StepRecord& record, const ViewRecord& view,
                         StoragePrecision precision, Imf::Compression compression,
                         const std::string& relative_path, std::vector<std::string>& part_names) {
    const std::string where = "step " + std::to_string(record.step) + " view " +
                              std::to_string(view.view_index) + " (" + relative_path + ")";
    const std::vector<FramedPart> parts = view_parts(view, precision, where);
    const Imath::Box2i display = display_window(parts);
    std::vector<Imf::Header> headers;
    part_names.clear();
    for (const FramedPart& part : parts) {
        headers.push_back(part_header(part, display, compression, record, view));
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
            write_part_pixels(file, static_cast<int>(p), parts[p].source);
        }
    } catch (const std::exception& error) {
        fail<IoError>("cannot encode EXR \"", relative_path, "\" part \"", current_part,
                      "\": ", error.what());
    }
    return std::move(stream.bytes());
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
}  // namespace insitu::archive_format
