// The timestep proxy archive, writing side (DESIGN.md "Archive"; names in archive_format.hpp).
//
// Crash safety: every file is written to a temp file in its final folder, fsync'ed, renamed into
// place and the folder fsync'ed, so a file name in the archive always holds complete bytes. The
// indexes (manifest.json, then data.csv) are rewritten whole, the same way, only after every file
// of the step is in place: a run killed at any moment leaves indexes that name complete files only.
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <glm/trigonometric.hpp>
#include <memory>
#include <set>
#include <sstream>

#include "archive/archive_format.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"

// libinsitu/CMakeLists.txt passes project(VERSION) as INSITU_VERSION.
#ifndef INSITU_VERSION
#error "INSITU_VERSION must be defined by the build (libinsitu/CMakeLists.txt)"
#endif

namespace insitu {

namespace fs = std::filesystem;
namespace af = archive_format;

std::uint64_t StepWriteResult::bytes() const {
    std::uint64_t total = 0;
    for (const WrittenFile& file : files) total += file.bytes;
    return total;
}

namespace archive_format {

namespace {
std::string step_stem(std::int64_t step, int view) {
    char stem[64];
    std::snprintf(stem, sizeof stem, "step%06lld_view%d", static_cast<long long>(step), view);
    return stem;
}
}  // namespace

std::string proxy_relative_path(std::int64_t step, int view) {
    return std::string(kProxyFolder) + "/" + step_stem(step, view) + ".exr";
}

std::string preview_relative_path(std::int64_t step, int view) {
    return std::string(kPreviewFolder) + "/" + step_stem(step, view) + ".png";
}

}  // namespace archive_format

namespace {

// ---------------------------------------------------------------------------------------------
// Durable files

std::string errno_text(int error) {
    return std::strerror(error);
}

void fsync_directory(const fs::path& directory) {
    const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        fail<IoError>("cannot open directory \"", directory.string(),
                      "\" to sync it: ", errno_text(errno));
    const int status = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (status != 0) {
        fail<IoError>("cannot sync directory \"", directory.string(), "\": ", errno_text(error));
    }
}

/// A temp file beside `final_path`, removed unless commit() renamed it into place.
class TempFile {
public:
    explicit TempFile(fs::path final_path) : final_(std::move(final_path)) {
        // pid + counter: unique within the folder without asking the file system.
        static std::atomic<unsigned> counter{0};
        temp_ = final_.parent_path() /
                (std::string(af::kTempPrefix) + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++) + "-" + final_.filename().string());
    }
    ~TempFile() {
        if (!committed_) ::unlink(temp_.c_str());
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;

    const fs::path& temp() const { return temp_; }

    void write(const void* data, std::size_t size) {
        const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) failed("create", errno);
        const char* bytes = static_cast<const char*>(data);
        std::size_t done = 0;
        while (done < size) {
            const ssize_t written = ::write(fd, bytes + done, size - done);
            if (written < 0) {
                if (errno == EINTR) continue;
                const int error = errno;
                ::close(fd);
                failed("write", error);
            }
            done += static_cast<std::size_t>(written);
        }
        sync_and_close(fd);
    }

    /// fsync()s a temp file someone else wrote (write_png).
    void sync() {
        const int fd = ::open(temp_.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) failed("reopen", errno);
        sync_and_close(fd);
    }

    void commit() {
        if (::rename(temp_.c_str(), final_.c_str()) != 0) failed("rename", errno);
        committed_ = true;
        fsync_directory(final_.parent_path());
    }

private:
    void sync_and_close(int fd) {
        if (::fsync(fd) != 0) {
            const int error = errno;
            ::close(fd);
            failed("sync", error);
        }
        // close() reports deferred write errors on some file systems (NFS).
        if (::close(fd) != 0) failed("close", errno);
    }
    [[noreturn]] void failed(const char* what, int error) const {
        fail<IoError>("cannot write \"", final_.string(), "\": ", what, " of temp file \"",
                      temp_.filename().string(), "\" failed: ", errno_text(error));
    }

    fs::path final_;
    fs::path temp_;
    bool committed_ = false;
};

void write_file_atomically(const fs::path& path, const std::string& bytes) {
    TempFile file(path);
    file.write(bytes.data(), bytes.size());
    file.commit();
}

// ---------------------------------------------------------------------------------------------
// OpenEXR encoding

/// Collects the encoded EXR in memory, so that the bytes are checksummed and written by the same
/// durable path as every other file (errors such as EFBIG or ENOSPC come back with errno).
class MemoryOutputStream : public Imf::OStream {
public:
    explicit MemoryOutputStream(const std::string& name) : Imf::OStream(name.c_str()) {}
    void write(const char c[], int n) override {
        if (position_ + n > bytes_.size()) bytes_.resize(position_ + n);
        std::memcpy(&bytes_[position_], c, static_cast<std::size_t>(n));
        position_ += static_cast<std::size_t>(n);
    }
    std::uint64_t tellp() override { return position_; }
    void seekp(std::uint64_t position) override { position_ = position; }
    std::string& bytes() { return bytes_; }

private:
    std::string bytes_;
    std::size_t position_ = 0;
};

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

nlohmann::json vec_json(const glm::dvec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

/// The camera a frame was rendered with: its orbit parameters (derived from its own vectors, so
/// they describe exactly this camera, e.g. the orthographic base of a distortion camera) and its
/// vectors. The reader rebuilds the Camera from both and checks they agree.
nlohmann::json camera_json(const Camera& camera) {
    nlohmann::json json{
        {"projection", to_string(camera.projection())},
        {"azimuth", camera.azimuth_deg()},
        {"elevation", camera.elevation_deg()},
        {"size", {camera.width(), camera.height()}},
        {"position", vec_json(camera.position())},
        {"forward", vec_json(camera.forward())},
        {"right", vec_json(camera.right())},
        {"up", vec_json(camera.up())},
        {"half_width", camera.half_width()},
        {"half_height", camera.half_height()},
        {"orbit_center", vec_json(camera.orbit_center())},
        {"orbit_radius", camera.orbit_radius()}};
    if (camera.projection() == Projection::perspective) {
        json["fov"] = glm::degrees(2.0 * std::atan(camera.half_height()));
    }
    return json;
}

nlohmann::json view_config_json(const ViewConfig& view) {
    return {{"azimuth", view.orbit.azimuth_deg},
            {"elevation", view.orbit.elevation_deg},
            {"camera", to_string(view.orbit.projection)},
            {"fov", view.orbit.fov_y_deg},
            {"size", {view.orbit.width, view.orbit.height}},
            {"distortion_tilt", view.distortion_tilt_deg}};
}

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
    nlohmann::json training_function;  ///< train<k> parts only
    const ColourModel* model = nullptr;  ///< model parts only
    /// Pixels made for the part (the model's table as an image); shared so that channel
    /// pointers stay valid when the part is moved.
    std::shared_ptr<const Image> storage{};
};

void add_channels(PartSource& part, const Image& image, const char* suffix, Imf::PixelType type) {
    for (int c = 0; c < image.channels; ++c) {
        part.channels.push_back({af::interval_channel(part.name, suffix, c), &image, c, type});
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
        PartSource part{af::part_name(base, multi), {}, {}};
        for (std::size_t k = 0; k < layers.size(); ++k) {
            if (layers[k].channels != 1 || layers[k].pixels.empty()) {
                fail<InvalidArgument>(where, ": ", part.name, " layer ", k, " has ",
                                      layers[k].channels, " channels and ", layers[k].pixel_count(),
                                      " pixels (expected 1 channel)");
            }
            part.channels.push_back(
                {af::layer_channel(part.name, static_cast<int>(k)), &layers[k], 0, Imf::FLOAT});
        }
        parts.push_back(std::move(part));
    };
    layers_part(af::kDepthPart, frame.depth_layers);
    if (multi) layers_part(af::kDistortionPart, frame.distortion_layers);

    PartSource attenuation{af::part_name(af::kAttenuationPart, multi), {}, {}};
    const Image* interval_images[3] = {&frame.attenuation, &frame.mean_depth, &frame.optical_depth};
    const char* interval_suffixes[3] = {af::kAttenuationChannel, af::kMeanDepthChannel,
                                        af::kOpticalDepthChannel};
    int interval_count = -1;
    for (int i = 0; i < 3; ++i) {
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
    if (!attenuation.channels.empty()) parts.push_back(std::move(attenuation));

    for (std::size_t t = 0; t < frame.training.size(); ++t) {
        const Image& image = frame.training[t];
        const std::string name = af::kTrainingPartPrefix + std::to_string(t);
        if (image.channels != 4 || image.pixels.empty()) {
            fail<InvalidArgument>(where, ": training image ", t, " has ", image.channels,
                                  " channels and ", image.pixel_count(), " pixels (expected RGBA)");
        }
        PartSource part{name, {}, nullptr};
        for (int c = 0; c < 4; ++c) {
            part.channels.push_back({name + af::kTrainingChannels[c], &image, c, compact});
        }
        if (t < view.training_transfer_functions.size()) {
            part.training_function = view.training_transfer_functions[t].to_json();
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
        PartSource part{af::part_name(af::kModelPart, multi), {}, {}, &model, table};
        part.channels.push_back({part.name + af::kModelChannel, table.get(), 0, Imf::FLOAT});
        parts.push_back(std::move(part));
    }
    for (const PartSource& part : parts) check_same_size(part, where);
    return parts;
}

/// The frame-level attributes, on every part of that frame so that each part describes itself.
void add_frame_attributes(Imf::Header& header, const StepRecord& record, const ViewRecord& view,
                          const ProxyFrame& frame) {
    header.insert(af::kSchemaAttribute, Imf::IntAttribute(kArchiveSchemaVersion));
    // Steps are 64-bit; EXR has no 64-bit integer attribute, and a decimal string is exact.
    header.insert(af::kStepAttribute, Imf::StringAttribute(std::to_string(record.step)));
    header.insert(af::kTimeAttribute, Imf::DoubleAttribute(record.time));
    header.insert(af::kFieldAttribute, Imf::StringAttribute(record.field));
    header.insert(af::kViewAttribute, Imf::IntAttribute(view.view_index));
    header.insert(af::kViewConfigAttribute,
                  Imf::StringAttribute(view_config_json(view.view).dump()));
    header.insert(af::kPerspectiveAttribute,
                  Imf::StringAttribute(frame.multi_perspective ? "multi" : "single"));
    header.insert(af::kCameraAttribute, Imf::StringAttribute(camera_json(frame.camera).dump()));
    if (frame.multi_perspective) {
        header.insert(af::kTiltAttribute, Imf::DoubleAttribute(frame.distortion_tilt_deg));
    }
    // JSON keeps doubles exact (shortest round-trip form); a FloatVectorAttribute would not.
    header.insert(af::kIsovaluesAttribute,
                  Imf::StringAttribute(nlohmann::json(frame.isovalues).dump()));
    if (frame.intervals) {
        header.insert(af::kIntervalsAttribute,
                      Imf::StringAttribute(frame.intervals->to_json().dump()));
    }
    header.insert(af::kTransferFunctionAttribute,
                  Imf::StringAttribute(view.transfer_function.to_json().dump()));
    nlohmann::json training = nlohmann::json::array();
    for (const TransferFunction& tf : view.training_transfer_functions) {
        training.push_back(tf.to_json());
    }
    header.insert(af::kTrainingFunctionsAttribute, Imf::StringAttribute(training.dump()));
}

/// Encodes the multi-part EXR of one view; returns its bytes and the part names in file order.
std::string encode_view(const StepRecord& record, const ViewRecord& view,
                        const InstrumentConfig& config, Imf::Compression compression,
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
        for (PartSource& part : frame_parts(**frame, view, config.precision, where)) {
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
        for (const ChannelSource& channel : part.source.channels) {
            header.channels().insert(channel.name, Imf::Channel(channel.type));
        }
        add_frame_attributes(header, record, view, *part.frame);
        if (!part.source.training_function.is_null()) {
            header.insert(af::kTrainingFunctionAttribute,
                          Imf::StringAttribute(part.source.training_function.dump()));
        }
        if (part.source.model) {
            header.insert(af::kModelIntervalsAttribute,
                          Imf::IntAttribute(part.source.model->intervals()));
            header.insert(af::kModelClustersAttribute,
                          Imf::IntAttribute(part.source.model->clusters()));
            header.insert(af::kModelLayoutAttribute, Imf::StringAttribute(af::kModelLayout));
            nlohmann::json functions = nlohmann::json::array();
            for (const TransferFunction& tf : view.training_transfer_functions) {
                functions.push_back(tf.to_json());
            }
            header.insert(af::kModelFunctionsAttribute, Imf::StringAttribute(functions.dump()));
        }
        headers.push_back(std::move(header));
        part_names.push_back(part.source.name);
    }

    MemoryOutputStream stream(relative_path);
    std::string current_part;
    try {
        Imf::MultiPartOutputFile file(stream, headers.data(), static_cast<int>(headers.size()));
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
// Indexes

/// Shortest text that reads back as the same double (Cinema viewers parse these columns).
std::string number_text(const nlohmann::json& number) {
    return number.dump();
}

std::string data_csv(const nlohmann::json& manifest) {
    // Cinema Spec D: header row, parameter columns, FILE last (a PNG, which Cinema viewers read).
    std::string csv = "time,step,view,phi,theta,proxy_exr,FILE\n";
    for (const nlohmann::json& step : manifest.at("steps")) {
        for (const nlohmann::json& view : step.at("views")) {
            std::string exr, png;
            for (const nlohmann::json& file : view.at("files")) {
                if (file.at("kind") == af::kProxyKind) exr = file.at("path").get<std::string>();
                if (file.at("kind") == af::kPreviewKind) png = file.at("path").get<std::string>();
            }
            csv += number_text(step.at("time")) + "," + number_text(step.at("step")) + "," +
                   number_text(view.at("view")) + "," + number_text(view.at("phi")) + "," +
                   number_text(view.at("theta")) + "," + exr + "," + png + "\n";
        }
    }
    return csv;
}

std::string manifest_text(const nlohmann::json& manifest) {
    return manifest.dump(2) + "\n";
}

nlohmann::json file_entry(const WrittenFile& file, const char* kind) {
    return {
        {"kind", kind}, {"path", file.relative_path}, {"bytes", file.bytes}, {"crc32", file.crc32}};
}

WrittenFile place_file(const fs::path& archive, const std::string& relative_path,
                       const std::string& bytes) {
    write_file_atomically(archive / relative_path, bytes);
    return {relative_path, bytes.size(), af::crc32_of(bytes.data(), bytes.size())};
}

/// write_png writes its own file, so it writes the temp file; then it is synced and renamed.
WrittenFile place_png(const fs::path& archive, const std::string& relative_path,
                      const Image& preview) {
    TempFile file(archive / relative_path);
    try {
        write_png(file.temp().string(), preview);
    } catch (const IoError& error) {
        fail<IoError>("cannot write \"", (archive / relative_path).string(), "\": ", error.what());
    }
    file.sync();
    const std::vector<char> bytes = af::read_whole_file(file.temp().string());
    file.commit();
    return {relative_path, bytes.size(), af::crc32_of(bytes.data(), bytes.size())};
}

void remove_leftover_temp_files(const fs::path& archive) {
    for (const fs::path& folder :
         {archive, archive / af::kProxyFolder, archive / af::kPreviewFolder}) {
        std::error_code error;
        for (fs::directory_iterator it(folder, error), end; !error && it != end;
             it.increment(error)) {
            if (it->path().filename().string().rfind(af::kTempPrefix, 0) == 0) {
                std::error_code ignored;  // best effort: a leftover is harmless, only clutter
                fs::remove(it->path(), ignored);
            }
        }
    }
}

void validate_record(const StepRecord& record, const ArchiveWriter& writer) {
    const std::string where = "step " + std::to_string(record.step);
    if (record.step < 0) {
        fail<InvalidArgument>(where, ": step numbers must be >= 0 (they name archive files)");
    }
    if (writer.contains(record.step)) {
        fail<InvalidArgument>(where, ": duplicate step, already in archive \"", writer.path(),
                              "\"");
    }
    if (record.views.empty()) fail<InvalidArgument>(where, ": no views");
    std::set<int> seen;
    for (const ViewRecord& view : record.views) {
        if (view.view_index < 0 || !seen.insert(view.view_index).second) {
            fail<InvalidArgument>(where, ": view index ", view.view_index,
                                  " is negative or repeated");
        }
        // data.csv's FILE column must name a PNG for every row (Cinema Spec D).
        if (view.preview.pixels.empty()) {
            fail<InvalidArgument>(where, " view ", view.view_index,
                                  ": no preview image (data.csv's FILE column needs one)");
        }
        if (view.preview.channels != 1 && view.preview.channels != 3 &&
            view.preview.channels != 4) {
            fail<InvalidArgument>(where, " view ", view.view_index, ": preview has ",
                                  view.preview.channels, " channels (expected 1, 3 or 4)");
        }
    }
}

}  // namespace

ArchiveWriter::ArchiveWriter(const InstrumentConfig& config)
    : path_(config.archive), config_(config) {
    parse_compression(config_.compression);  // fail early, before touching the disk
    if (path_.empty()) fail<InvalidArgument>("archive: empty path");
    const fs::path archive(path_);
    for (const fs::path& folder :
         {archive, archive / af::kProxyFolder, archive / af::kPreviewFolder}) {
        std::error_code error;
        fs::create_directories(folder, error);
        if (error || !fs::is_directory(folder)) {
            fail<IoError>("cannot create archive directory \"", folder.string(),
                          "\": ", error ? error.message() : "exists and is not a directory");
        }
    }

    nlohmann::json configuration = config_.to_json();
    nlohmann::json manifest;
    if (fs::exists(archive / af::kManifestFile)) {
        // A restarted run appends. A corrupt manifest throws here and is never overwritten.
        manifest = af::read_manifest(path_);
        if (manifest.at("configuration") != configuration) {
            manifest["previous_configurations"].push_back(manifest.at("configuration"));
        }
    } else {
        manifest = {{"schema_version", kArchiveSchemaVersion}, {"steps", nlohmann::json::array()}};
    }
    manifest["producer"] = std::string("libinsitu ") + INSITU_VERSION;
    manifest["configuration"] = std::move(configuration);
    remove_leftover_temp_files(archive);
    // Writing both indexes now makes a fresh archive open (with no steps), catches an unwritable
    // directory at start-up, and brings a data.csv a crash left one step behind up to date.
    write_file_atomically(archive / af::kManifestFile, manifest_text(manifest));
    write_file_atomically(archive / af::kCsvFile, data_csv(manifest));
    for (const nlohmann::json& entry : manifest.at("steps")) {
        steps_.push_back(entry.at("step").get<std::int64_t>());
    }
    std::sort(steps_.begin(), steps_.end());
}

bool ArchiveWriter::contains(std::int64_t step) const {
    return std::binary_search(steps_.begin(), steps_.end(), step);
}

StepWriteResult ArchiveWriter::write(const StepRecord& record) {
    validate_record(record, *this);
    const Imf::Compression compression = parse_compression(config_.compression);
    const fs::path archive(path_);

    StepWriteResult result;
    nlohmann::json step_entry{{"step", record.step},
                              {"time", record.time},
                              {"field", record.field},
                              {"views", nlohmann::json::array()}};
    bool indexed = false;
    try {
        for (const ViewRecord& view : record.views) {
            const std::string exr_path = af::proxy_relative_path(record.step, view.view_index);
            std::vector<std::string> parts;
            const std::string exr =
                encode_view(record, view, config_, compression, exr_path, parts);
            result.files.push_back(place_file(archive, exr_path, exr));
            result.files.push_back(place_png(
                archive, af::preview_relative_path(record.step, view.view_index), view.preview));
            step_entry["views"].push_back(
                {{"view", view.view_index},
                 {"phi", view.view.orbit.azimuth_deg},
                 {"theta", view.view.orbit.elevation_deg},
                 {"parts", parts},
                 {"files",
                  {file_entry(result.files[result.files.size() - 2], af::kProxyKind),
                   file_entry(result.files.back(), af::kPreviewKind)}}});
        }

        // Read back rather than kept: memory stays flat over a long run (the file is ours,
        // written by this writer, and validated again on the way in).
        nlohmann::json manifest = af::read_manifest(path_);
        nlohmann::json& steps = manifest["steps"];
        const auto position = std::find_if(steps.begin(), steps.end(), [&](const auto& entry) {
            return entry.at("step").template get<std::int64_t>() > record.step;
        });
        steps.insert(position, std::move(step_entry));
        write_file_atomically(archive / af::kManifestFile, manifest_text(manifest));
        // From here the step is in the archive, whatever happens to data.csv.
        steps_.insert(std::upper_bound(steps_.begin(), steps_.end(), record.step), record.step);
        indexed = true;
        write_file_atomically(archive / af::kCsvFile, data_csv(manifest));
    } catch (...) {
        if (!indexed) {
            // Nothing names these files; remove them so the archive is as it was (best effort,
            // a leftover would only be clutter that the next write of this step replaces).
            for (const WrittenFile& file : result.files) {
                std::error_code ignored;
                fs::remove(archive / file.relative_path, ignored);
            }
        }
        throw;
    }
    return result;
}

}  // namespace insitu
