// The timestep proxy archive, reading side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Everything read is validated: the manifest's shape, each file's size and CRC-32 against the
// manifest before it is parsed, and every EXR part, channel and attribute the frame needs.
// OpenEXR reports damage with Iex exceptions; each is turned into an IoError naming the file and
// the part, so a corrupt, truncated or foreign file is a clear error, never a crash or garbage.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <iterator>
#include <map>
#include <set>

#include "archive/archive_format.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace fs = std::filesystem;
namespace af = archive_format;

namespace archive_format {

std::uint32_t crc32_of(const void* data, std::size_t size) {
    // zlib's crc32 takes uInt lengths; feed it in chunks so files over 4 GiB are fine.
    uLong crc = ::crc32(0L, Z_NULL, 0);
    const auto* bytes = static_cast<const Bytef*>(data);
    while (size > 0) {
        const uInt chunk = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
        crc = ::crc32(crc, bytes, chunk);
        bytes += chunk;
        size -= chunk;
    }
    return static_cast<std::uint32_t>(crc);
}

std::vector<char> read_whole_file(const std::string& path) {
    std::error_code error;
    if (!fs::is_regular_file(path, error)) {
        fail<IoError>("cannot read \"", path,
                      "\": ", fs::exists(path, error) ? "not a regular file" : "no such file");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<IoError>("cannot open \"", path, "\"");
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) fail<IoError>("cannot read \"", path, "\"");
    return bytes;
}

namespace {

/// What a manifest key must hold.
enum class Expect { number, integer, count, crc32, string, object, array };

bool holds(const nlohmann::json& value, Expect expect) {
    switch (expect) {
        case Expect::number:
            return value.is_number();
        case Expect::integer:
            return value.is_number_integer();
        case Expect::count:
            return value.is_number_unsigned();
        case Expect::crc32:
            return value.is_number_unsigned() && value.get<std::uint64_t>() <= 0xFFFFFFFFu;
        case Expect::string:
            return value.is_string();
        case Expect::object:
            return value.is_object();
        case Expect::array:
            return value.is_array();
    }
    return false;
}

/// Checks one key of a JSON object; ParseError names the file and the dotted key.
const nlohmann::json& require(const nlohmann::json& object, const char* key, Expect expect,
                              const std::string& file, const std::string& where) {
    const std::string name = where.empty() ? key : where + "." + key;
    if (!object.is_object() || !object.contains(key)) {
        fail<ParseError>("\"", file, "\": missing key \"", name, "\"");
    }
    const nlohmann::json& value = object.at(key);
    if (!holds(value, expect)) {
        fail<ParseError>("\"", file, "\": key \"", name, "\" has the wrong type: ", value.dump());
    }
    return value;
}

/// Paths in the manifest must stay inside the archive.
void check_relative_path(const std::string& path, const std::string& file,
                         const std::string& where) {
    const fs::path relative(path);
    bool escapes = path.empty() || relative.is_absolute();
    for (const fs::path& component : relative) escapes = escapes || component == "..";
    if (escapes) {
        fail<ParseError>("\"", file, "\": ", where, ".path \"", path,
                         "\" is not a relative path inside the archive");
    }
}

}  // namespace

nlohmann::json read_manifest(const std::string& archive_path) {
    const std::string file = (fs::path(archive_path) / kManifestFile).string();
    std::error_code error;
    if (!fs::is_directory(archive_path, error)) {
        fail<IoError>("archive \"", archive_path, "\" is not a directory");
    }
    const std::vector<char> bytes = read_whole_file(file);
    nlohmann::json manifest;
    try {
        manifest = nlohmann::json::parse(bytes.begin(), bytes.end());
    } catch (const nlohmann::json::exception& parse_error) {
        fail<ParseError>("\"", file, "\": not valid JSON: ", parse_error.what());
    }
    if (!manifest.is_object()) fail<ParseError>("\"", file, "\": not a JSON object");
    const auto version = require(manifest, "schema_version", Expect::integer, file, "");
    if (version.get<long long>() != kArchiveSchemaVersion) {
        fail<ParseError>("\"", file, "\": schema_version ", version.dump(),
                         " (this libinsitu reads ", kArchiveSchemaVersion, ")");
    }
    require(manifest, "producer", Expect::string, file, "");
    require(manifest, "configuration", Expect::object, file, "");
    std::set<std::int64_t> steps_seen;
    const auto& steps = require(manifest, "steps", Expect::array, file, "");
    for (std::size_t s = 0; s < steps.size(); ++s) {
        const std::string where = "steps[" + std::to_string(s) + "]";
        const auto& step = steps[s];
        const auto number = require(step, "step", Expect::integer, file, where);
        if (!steps_seen.insert(number.get<std::int64_t>()).second) {
            fail<ParseError>("\"", file, "\": ", where, ": step ", number.dump(), " is repeated");
        }
        require(step, "time", Expect::number, file, where);
        require(step, "field", Expect::string, file, where);
        std::set<int> views_seen;
        const auto& views = require(step, "views", Expect::array, file, where);
        for (std::size_t v = 0; v < views.size(); ++v) {
            const std::string view_where = where + ".views[" + std::to_string(v) + "]";
            const auto& view = views[v];
            const auto index = require(view, "view", Expect::count, file, view_where);
            if (!views_seen.insert(index.get<int>()).second) {
                fail<ParseError>("\"", file, "\": ", view_where, ": view ", index.dump(),
                                 " is repeated");
            }
            require(view, "phi", Expect::number, file, view_where);
            require(view, "theta", Expect::number, file, view_where);
            for (const auto& part : require(view, "parts", Expect::array, file, view_where)) {
                if (!part.is_string()) {
                    fail<ParseError>("\"", file, "\": ", view_where, ".parts: ", part.dump(),
                                     " is not a part name");
                }
            }
            std::set<std::string> kinds;
            const auto& files = require(view, "files", Expect::array, file, view_where);
            for (std::size_t f = 0; f < files.size(); ++f) {
                const std::string file_where = view_where + ".files[" + std::to_string(f) + "]";
                kinds.insert(require(files[f], "kind", Expect::string, file, file_where));
                check_relative_path(require(files[f], "path", Expect::string, file, file_where),
                                    file, file_where);
                require(files[f], "bytes", Expect::count, file, file_where);
                require(files[f], "crc32", Expect::crc32, file, file_where);
            }
            for (const char* kind : {kProxyKind, kPreviewKind}) {
                if (!kinds.count(kind)) {
                    fail<ParseError>("\"", file, "\": ", view_where, " lists no ", kind, " file");
                }
            }
        }
    }
    return manifest;
}

}  // namespace archive_format

namespace {

/// Lets OpenEXR parse a file already read (and checksummed) into memory.
class MemoryInputStream : public Imf::IStream {
public:
    MemoryInputStream(const std::vector<char>& bytes, const std::string& name)
        : Imf::IStream(name.c_str()), bytes_(bytes) {}
    bool read(char c[], int n) override {
        if (n < 0 || position_ > bytes_.size() || bytes_.size() - position_ < std::size_t(n)) {
            throw std::runtime_error("unexpected end of file at byte " + std::to_string(position_));
        }
        std::memcpy(c, bytes_.data() + position_, static_cast<std::size_t>(n));
        position_ += static_cast<std::size_t>(n);
        return position_ < bytes_.size();
    }
    std::uint64_t tellg() override { return position_; }
    void seekg(std::uint64_t position) override { position_ = position; }

private:
    const std::vector<char>& bytes_;
    std::uint64_t position_ = 0;
};

/// A file of one view as the manifest lists it.
struct ListedFile {
    std::string absolute_path;
    std::uint64_t bytes = 0;
    std::uint32_t crc32 = 0;
};

ListedFile listed_file(const std::string& archive, const nlohmann::json& view, const char* kind) {
    for (const nlohmann::json& file : view.at("files")) {
        if (file.at("kind") == kind) {
            return {(fs::path(archive) / file.at("path").get<std::string>()).string(),
                    file.at("bytes").get<std::uint64_t>(), file.at("crc32").get<std::uint32_t>()};
        }
    }
    // read_manifest() guarantees both kinds; reaching this is a bug, not bad input.
    fail<Error>("archive \"", archive, "\": view lists no ", kind, " file");
}

/// The file's bytes, after checking them against the manifest (a file replaced, truncated or
/// damaged since it was written is reported before anything parses it).
std::vector<char> read_checked(const ListedFile& file) {
    std::vector<char> bytes = af::read_whole_file(file.absolute_path);
    if (bytes.size() != file.bytes) {
        fail<IoError>("\"", file.absolute_path, "\": ", bytes.size(),
                      " bytes, the manifest records ", file.bytes, " (truncated or replaced)");
    }
    const std::uint32_t crc = af::crc32_of(bytes.data(), bytes.size());
    if (crc != file.crc32) {
        fail<IoError>("\"", file.absolute_path, "\": CRC-32 ", crc, ", the manifest records ",
                      file.crc32, " (corrupt)");
    }
    return bytes;
}

// ---------------------------------------------------------------------------------------------
// One EXR part

/// Where an error happened, for messages: file and part.
struct PartContext {
    const std::string& file;
    std::string part;
    [[noreturn]] void error(const std::string& what) const {
        fail<IoError>("\"", file, "\" part \"", part, "\": ", what);
    }
};

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

glm::dvec3 vec_from_json(const nlohmann::json& json) {
    return {json.at(0).get<double>(), json.at(1).get<double>(), json.at(2).get<double>()};
}

/// Rebuilds a Camera from its attribute (see camera_json in archive_writer.cpp). Camera has no
/// public setters, so the orbit factory is fed bounds with the centre and radius that give the
/// stored camera, then the result is checked against the stored vectors.
Camera camera_from_json(const nlohmann::json& json, const PartContext& where) {
    try {
        OrbitView view;
        view.projection = parse_projection(json.at("projection").get<std::string>());
        view.azimuth_deg = json.at("azimuth").get<double>();
        view.elevation_deg = json.at("elevation").get<double>();
        view.width = json.at("size").at(0).get<int>();
        view.height = json.at("size").at(1).get<int>();
        if (view.projection == Projection::perspective)
            view.fov_y_deg = json.at("fov").get<double>();
        const glm::dvec3 position = vec_from_json(json.at("position"));
        const glm::dvec3 forward = vec_from_json(json.at("forward"));
        const double half_width = json.at("half_width").get<double>();
        const double half_height = json.at("half_height").get<double>();
        // Orthographic: the smaller half side is the bounding radius and the camera plane
        // touches the sphere. Perspective: only the eye matters; any radius works, at the
        // distance where that sphere fits the smaller field of view (camera.cpp).
        // Archives record the orbit's sphere (so a new view orbits the same centre); without
        // it the perspective centre is unknown and any point on the view axis stands in.
        double radius = 1.0, distance = 1.0;
        if (view.projection == Projection::orthographic) {
            radius = distance = std::min(half_width, half_height);
        } else {
            if (json.contains("orbit_radius")) radius = json.at("orbit_radius").get<double>();
            distance = radius / std::sin(std::atan(std::min(half_width, half_height)));
        }
        const glm::dvec3 center = json.contains("orbit_center")
                                      ? vec_from_json(json.at("orbit_center"))
                                      : position + distance * forward;
        const glm::dvec3 half_extent(radius / std::sqrt(3.0));
        const Camera camera =
            Camera::orbit(view, Bounds{center - half_extent, center + half_extent});

        // Round trips through degrees lose a few ulps; anything beyond 1e-9 of the scene's scale
        // means the attribute does not describe a camera this library made.
        const double scale = std::max({1.0, glm::length(position), half_width, half_height});
        const double tolerance = 1e-9 * scale;
        const double mismatch = std::max(
            {glm::length(camera.position() - position), glm::length(camera.forward() - forward),
             glm::length(camera.right() - vec_from_json(json.at("right"))),
             glm::length(camera.up() - vec_from_json(json.at("up"))),
             std::abs(camera.half_width() - half_width),
             std::abs(camera.half_height() - half_height)});
        if (!(mismatch <= tolerance)) {
            where.error("attribute \"" + std::string(af::kCameraAttribute) +
                        "\" is inconsistent (vectors differ by " + std::to_string(mismatch) +
                        " from its orbit parameters)");
        }
        return camera;
    } catch (const IoError&) {
        throw;
    } catch (const std::exception& error) {
        where.error("attribute \"" + std::string(af::kCameraAttribute) + "\": " + error.what());
    }
}

/// The frame-level metadata every part of a frame carries.
void read_frame_attributes(const Imf::Header& header, ProxyFrame& frame, const PartContext& where) {
    const auto* schema = header.findTypedAttribute<Imf::IntAttribute>(af::kSchemaAttribute);
    if (!schema) where.error(std::string("no int attribute \"") + af::kSchemaAttribute + "\"");
    if (schema->value() != kArchiveSchemaVersion) {
        where.error("schema version " + std::to_string(schema->value()) +
                    " (this libinsitu reads " + std::to_string(kArchiveSchemaVersion) + ")");
    }
    frame.camera = camera_from_json(json_attribute(header, af::kCameraAttribute, where), where);
    if (frame.multi_perspective) {
        const auto* tilt = header.findTypedAttribute<Imf::DoubleAttribute>(af::kTiltAttribute);
        if (!tilt) where.error(std::string("no double attribute \"") + af::kTiltAttribute + "\"");
        frame.distortion_tilt_deg = tilt->value();
    }
    try {
        frame.isovalues =
            json_attribute(header, af::kIsovaluesAttribute, where).get<std::vector<double>>();
        if (header.findTypedAttribute<Imf::StringAttribute>(af::kIntervalsAttribute)) {
            const nlohmann::json intervals = json_attribute(header, af::kIntervalsAttribute, where);
            frame.intervals = IntervalSet(intervals.at("edges").get<std::vector<double>>());
        }
    } catch (const IoError&) {
        throw;
    } catch (const std::exception& error) {
        where.error(std::string("isovalues or intervals attribute: ") + error.what());
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
    auto name_of = [&](int k) { return af::layer_channel(where.part, k); };
    const int count = count_channels(part.header().channels(), name_of);
    if (count == 0) where.error("no channel \"" + name_of(0) + "\"");
    const Image all = read_channels(part, names_of(count, name_of), where);
    std::vector<Image> layers(static_cast<std::size_t>(count), Image(all.width, all.height, 1));
    for (std::size_t p = 0; p < all.pixel_count(); ++p) {
        for (int k = 0; k < count; ++k) layers[k].pixels[p] = all.pixels[p * count + k];
    }
    return layers;
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

/// a_j, and z-mean and tau when present, of an "attenuation" part.
void read_attenuation(Imf::InputPart& part, ProxyFrame& frame, const PartContext& where) {
    const Imf::ChannelList& channels = part.header().channels();
    const char* suffixes[3] = {af::kAttenuationChannel, af::kMeanDepthChannel,
                               af::kOpticalDepthChannel};
    Image* targets[3] = {&frame.attenuation, &frame.mean_depth, &frame.optical_depth};
    int counts[3];
    std::vector<std::string> names;
    for (int i = 0; i < 3; ++i) {
        auto name_of = [&](int j) { return af::interval_channel(where.part, suffixes[i], j); };
        counts[i] = count_channels(channels, name_of);
        for (int j = 0; j < counts[i]; ++j) names.push_back(name_of(j));
    }
    const int intervals = std::max({counts[0], counts[1], counts[2]});
    for (int i = 0; i < 3; ++i) {
        if (counts[i] != 0 && counts[i] != intervals) {
            where.error("channels \"" + where.part + suffixes[i] +
                        "..\": " + std::to_string(counts[i]) + " intervals, expected " +
                        std::to_string(intervals));
        }
    }
    if (intervals == 0) {
        where.error("no channel \"" + af::interval_channel(where.part, suffixes[0], 0) + "\"");
    }
    const Image all = read_channels(part, names, where);
    int first = 0;
    for (int i = 0; i < 3; ++i) {
        if (counts[i] == 0) continue;
        *targets[i] = channel_range(all, first, counts[i]);
        first += counts[i];
    }
}

Image read_training(Imf::InputPart& part, const PartContext& where) {
    std::vector<std::string> names;
    for (const char* suffix : af::kTrainingChannels) {
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
    const auto* intervals =
        header.findTypedAttribute<Imf::IntAttribute>(af::kModelIntervalsAttribute);
    const auto* clusters =
        header.findTypedAttribute<Imf::IntAttribute>(af::kModelClustersAttribute);
    if (!intervals || !clusters) {
        where.error(std::string("no int attributes \"") + af::kModelIntervalsAttribute +
                    "\" and \"" + af::kModelClustersAttribute + "\"");
    }
    const std::string channel = where.part + af::kModelChannel;
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

// ---------------------------------------------------------------------------------------------
// PNG previews

float srgb_to_linear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

/// Decodes a preview the way write_png encoded it: 8-bit sRGB, straight alpha -> linear,
/// premultiplied; 1, 3 or 4 channels as stored (grey + alpha becomes RGBA).
Image decode_png(const std::vector<char>& bytes, const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) {
        fail<IoError>("\"", path, "\": not a readable PNG: ", png.message);
    }
    const bool alpha = png.format & PNG_FORMAT_FLAG_ALPHA;
    const bool colour = png.format & PNG_FORMAT_FLAG_COLOR;
    png.format = alpha ? PNG_FORMAT_RGBA : colour ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    const int channels = alpha ? 4 : colour ? 3 : 1;
    std::vector<png_byte> pixels(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr)) {
        const std::string message = png.message;
        png_image_free(&png);
        fail<IoError>("\"", path, "\": cannot decode PNG: ", message);
    }
    Image image(static_cast<int>(png.width), static_cast<int>(png.height), channels);
    for (std::size_t i = 0; i < image.pixel_count(); ++i) {
        const png_byte* in = &pixels[i * channels];
        float* out = &image.pixels[i * channels];
        const float a = alpha ? in[3] / 255.0f : 1.0f;
        for (int c = 0; c < std::min(channels, 3); ++c) out[c] = srgb_to_linear(in[c] / 255.0f) * a;
        if (alpha) out[3] = a;
    }
    return image;
}

}  // namespace

// -------------------------------------------------------------------------------------------------

ArchiveReader::ArchiveReader(const std::string& path)
    : path_(path), manifest_(af::read_manifest(path)) {}

InstrumentConfig ArchiveReader::configuration() const {
    const std::string file = (fs::path(path_) / af::kManifestFile).string();
    try {
        return InstrumentConfig::from_json(manifest_.at("configuration"));
    } catch (const std::exception& error) {
        fail<ParseError>("\"", file, "\": configuration: ", error.what());
    }
}

std::vector<std::int64_t> ArchiveReader::steps() const {
    std::vector<std::int64_t> steps;
    for (const nlohmann::json& step : manifest_.at("steps")) {
        steps.push_back(step.at("step").get<std::int64_t>());
    }
    std::sort(steps.begin(), steps.end());
    return steps;
}

int ArchiveReader::view_count() const {
    std::size_t count = 0;
    for (const nlohmann::json& step : manifest_.at("steps")) {
        count = std::max(count, step.at("views").size());
    }
    if (count == 0 && manifest_.at("configuration").contains("views") &&
        manifest_.at("configuration").at("views").is_array()) {
        count = manifest_.at("configuration").at("views").size();
    }
    return static_cast<int>(count);
}

namespace {
struct FoundView {
    const nlohmann::json* step;
    const nlohmann::json* view;
};

FoundView find_view(const nlohmann::json& manifest, const std::string& archive, std::int64_t step,
                    int view) {
    for (const nlohmann::json& step_entry : manifest.at("steps")) {
        if (step_entry.at("step").get<std::int64_t>() != step) continue;
        for (const nlohmann::json& view_entry : step_entry.at("views")) {
            if (view_entry.at("view").get<int>() == view) return {&step_entry, &view_entry};
        }
        fail<InvalidArgument>("archive \"", archive, "\": step ", step, " has no view ", view);
    }
    fail<InvalidArgument>("archive \"", archive, "\" has no step ", step);
}
}  // namespace

ArchivedView ArchiveReader::entry(std::int64_t step, int view) const {
    const FoundView found = find_view(manifest_, path_, step, view);
    ArchivedView result;
    result.step = step;
    result.time = found.step->at("time").get<double>();
    result.view_index = view;
    const fs::path root = fs::absolute(path_);
    result.exr_path = listed_file(root.string(), *found.view, af::kProxyKind).absolute_path;
    result.preview_path = listed_file(root.string(), *found.view, af::kPreviewKind).absolute_path;
    return result;
}

ProxyFrame ArchiveReader::load(std::int64_t step, int view, bool multi_perspective) const {
    const FoundView found = find_view(manifest_, path_, step, view);
    const ListedFile listed = listed_file(path_, *found.view, af::kProxyKind);
    std::vector<std::string> wanted;
    for (const nlohmann::json& part : found.view->at("parts")) {
        if (af::is_multi_part(part.get<std::string>()) == multi_perspective) {
            wanted.push_back(part.get<std::string>());
        }
    }
    if (wanted.empty()) {
        fail<InvalidArgument>("archive \"", path_, "\": step ", step, " view ", view, " has no ",
                              multi_perspective ? "multi" : "single", "-perspective proxies (",
                              listed.absolute_path, ")");
    }

    const std::vector<char> bytes = read_checked(listed);
    ProxyFrame frame;
    frame.multi_perspective = multi_perspective;
    PartContext where{listed.absolute_path, "(header)"};
    try {
        MemoryInputStream stream(bytes, listed.absolute_path);
        // No reconstruction of a damaged chunk offset table: damage is an error here.
        Imf::MultiPartInputFile file(stream, Imf::globalThreadCount(), false);
        std::map<std::string, int> parts;
        for (int p = 0; p < file.parts(); ++p) {
            if (file.header(p).hasName()) parts[file.header(p).name()] = p;
        }
        bool first = true;
        for (const std::string& name : wanted) {
            where.part = name;
            const auto found_part = parts.find(name);
            if (found_part == parts.end()) where.error("missing from the file");
            Imf::InputPart part(file, found_part->second);
            if (first) read_frame_attributes(part.header(), frame, where);
            first = false;
            const std::string base =
                multi_perspective ? name.substr(std::strlen(af::kMultiPrefix)) : name;
            if (base == af::kDepthPart) {
                frame.depth_layers = read_layers(part, where);
            } else if (base == af::kDistortionPart) {
                frame.distortion_layers = read_layers(part, where);
            } else if (base == af::kAttenuationPart) {
                read_attenuation(part, frame, where);
            } else if (base.rfind(af::kTrainingPartPrefix, 0) == 0 &&
                       base == af::kTrainingPartPrefix + std::to_string(frame.training.size())) {
                frame.training.push_back(read_training(part, where));
            } else if (base == af::kModelPart && !frame.colour_model) {
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

Image ArchiveReader::load_preview(std::int64_t step, int view) const {
    const FoundView found = find_view(manifest_, path_, step, view);
    const ListedFile listed = listed_file(path_, *found.view, af::kPreviewKind);
    return decode_png(read_checked(listed), listed.absolute_path);
}

std::vector<std::string> ArchiveReader::verify() const {
    std::vector<std::string> problems;
    for (const nlohmann::json& step : manifest_.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            for (const nlohmann::json& file : view.at("files")) {
                const std::string relative = file.at("path").get<std::string>();
                const ListedFile listed{(fs::path(path_) / relative).string(),
                                        file.at("bytes").get<std::uint64_t>(),
                                        file.at("crc32").get<std::uint32_t>()};
                try {
                    read_checked(listed);
                } catch (const IoError& error) {
                    problems.push_back(error.what());
                }
            }
        }
    }
    return problems;
}

}  // namespace insitu
