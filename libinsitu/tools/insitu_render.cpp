// insitu-render: renders a raw scalar volume with the ground-truth volume renderer (seed 002)
// into a PNG or EXR image, optionally with its first-hit depth.
//
// Exit status: 0 on success; 2 for bad arguments and bad input (unknown flag, malformed number,
// wrong raw file size, unreadable or malformed transfer function, unsupported extension);
// 1 for anything else (no OpenCL platform, a failed kernel launch, out of memory).
// Every failure is reported as one line on stderr that names the offending flag or value.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/render/volume_renderer.hpp"

namespace {

constexpr const char* kProgram = "insitu-render";
using insitu::cli::parse_finite;
using insitu::cli::parse_positive_integer;
using insitu::cli::split_exactly;
using insitu::cli::UsageError;

struct Arguments {
    std::string raw_path;
    insitu::Index3 dims{0, 0, 0};
    insitu::ScalarType type = insitu::ScalarType::float32;
    glm::dvec3 spacing_world{1.0};
    glm::dvec3 origin_world{0.0};
    std::string tf_path;
    insitu::OrbitView view;
    insitu::RenderSettings settings;
    std::string out_path;
    std::string depth_out_path;
};

// ---------------------------------------------------------------------------------------------
// Value parsers (arguments.hpp: each takes the whole token or fails).

insitu::Index3 parse_dims(const std::string& flag, const std::string& text) {
    const auto parts = split_exactly(flag, text, ',', 3, "NX,NY,NZ");
    return {parse_positive_integer(flag, parts[0], text),
            parse_positive_integer(flag, parts[1], text),
            parse_positive_integer(flag, parts[2], text)};
}

glm::dvec3 parse_vec3(const std::string& flag, const std::string& text, const char* shape) {
    const auto parts = split_exactly(flag, text, ',', 3, shape);
    return {parse_finite(flag, parts[0]), parse_finite(flag, parts[1]),
            parse_finite(flag, parts[2])};
}

void parse_size(const std::string& flag, const std::string& text, insitu::OrbitView& view) {
    // Kernels index pixels as int (y * width + x): 2^15 per side keeps that below 2^31.
    constexpr int kMaxSide = 1 << 15;
    const insitu::cli::PixelSize size = insitu::cli::parse_pixel_size(flag, text, kMaxSide);
    view.width = size.width;
    view.height = size.height;
}

/// Library parse errors (unknown type or projection) become usage errors naming the flag.
template <typename Parse>
auto parse_with_library(const std::string& flag, const std::string& text, Parse parse) {
    try {
        return parse(text);
    } catch (const insitu::Error& error) {
        throw UsageError(flag + ": " + error.what());
    }
}

std::string lowercase_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

void require_extension(const std::string& flag, const std::string& path,
                       const std::vector<std::string>& allowed) {
    const std::string ext = lowercase_extension(path);
    if (std::find(allowed.begin(), allowed.end(), ext) != allowed.end()) return;
    std::string list;
    for (const std::string& a : allowed) list += (list.empty() ? "" : " or ") + a;
    throw UsageError(flag + ": \"" + path + "\" has an unsupported extension (expected " + list +
                     ")");
}

// ---------------------------------------------------------------------------------------------
// The option table: one row per flag; help text and parsing both come from it.

using Option = insitu::cli::TableOption<Arguments>;

const std::vector<Option>& options() {
    using V = const std::string&;
    static const std::vector<Option> table = {
        {"--raw", "FILE", true, "raw volume, x fastest, little-endian", "",
         [](Arguments& a, V, V v) { a.raw_path = v; }},
        {"--dims", "NX,NY,NZ", true, "samples per axis", "",
         [](Arguments& a, V f, V v) { a.dims = parse_dims(f, v); }},
        {"--type", "TYPE", true, "float32, float64, uint8, uint16 or int16", "",
         [](Arguments& a, V f, V v) {
             a.type = parse_with_library(f, v, insitu::parse_scalar_type);
         }},
        {"--spacing", "SX,SY,SZ", false, "distance between samples in world units", "1,1,1",
         [](Arguments& a, V f, V v) { a.spacing_world = parse_vec3(f, v, "SX,SY,SZ"); }},
        {"--origin", "OX,OY,OZ", false, "world position of the first sample", "0,0,0",
         [](Arguments& a, V f, V v) { a.origin_world = parse_vec3(f, v, "OX,OY,OZ"); }},
        {"--tf", "TF.json", true, "transfer function JSON (see below)", "",
         [](Arguments& a, V, V v) { a.tf_path = v; }},
        {"--camera", "ortho|perspective", false, "projection", "ortho",
         [](Arguments& a, V f, V v) {
             a.view.projection = parse_with_library(f, v, insitu::parse_projection);
         }},
        {"--azimuth", "DEG", false, "orbit azimuth in degrees", "0: looking down -z",
         [](Arguments& a, V f, V v) { a.view.azimuth_deg = parse_finite(f, v); }},
        {"--elevation", "DEG", false, "orbit elevation in degrees, [-90, 90]", "0",
         [](Arguments& a, V f, V v) { a.view.elevation_deg = parse_finite(f, v); }},
        {"--fov", "DEG", false, "vertical field of view in degrees, perspective", "30",
         [](Arguments& a, V f, V v) { a.view.fov_y_deg = parse_finite(f, v); }},
        {"--size", "WxH", false, "image size in pixels", "512x512",
         [](Arguments& a, V f, V v) { parse_size(f, v, a.view); }},
        {"--step", "VOXELS", false, "ray step in units of the smallest spacing", "1",
         [](Arguments& a, V f, V v) { a.settings.step_voxels = parse_finite(f, v); }},
        {"--early-termination", "OPACITY", false, "stop a ray at this opacity (> 1: never)", "0.99",
         [](Arguments& a, V f, V v) { a.settings.early_termination_opacity = parse_finite(f, v); }},
        {"--shade", nullptr, false, "Phong shading with a headlight", "",
         [](Arguments& a, V, V) { a.settings.shading = true; }},
        {"--out", "OUT.png|OUT.exr", true, "image: 8-bit sRGB PNG or linear premultiplied EXR", "",
         [](Arguments& a, V f, V v) {
             require_extension(f, v, {".png", ".exr"});
             a.out_path = v;
         }},
        {"--depth-out", "DEPTH.exr", false, "first-hit depth (world units, +inf: no hit) as EXR Z",
         "none",
         [](Arguments& a, V f, V v) {
             require_extension(f, v, {".exr"});
             a.depth_out_path = v;
         }},
    };
    return table;
}

const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        insitu::cli::CommandHelp h;
        h.usage = std::string(kProgram) +
                  " --raw FILE --dims NX,NY,NZ --type TYPE --tf TF.json --out OUT.png|OUT.exr "
                  "[options]";
        h.description =
            "Renders a raw scalar volume by emission-absorption ray casting (libinsitu's ground "
            "truth).";
        h.options = insitu::cli::help_rows(options());
        h.notes =
            "TF.json: {\"points\": [[value, r, g, b, a], ...], \"unit_length\": 1.0}, a = "
            "opacity per unit_length world units.\n"
            "Exit status: 0 success, 2 bad arguments or input, 1 other failures.";
        return h;
    }();
    return help;
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments arguments;
    insitu::cli::parse_table(argc, argv, options(), arguments);
    return arguments;
}

// ---------------------------------------------------------------------------------------------

bool host_is_little_endian() {
    const std::uint16_t probe = 1;
    unsigned char first_byte = 0;
    std::copy_n(reinterpret_cast<const unsigned char*>(&probe), 1, &first_byte);
    return first_byte == 1;
}

/// Reads the whole raw file. The returned buffer comes from operator new, so it is aligned for
/// every scalar type, and the Field view made over it copies nothing.
std::vector<std::byte> read_raw_volume(const Arguments& arguments) {
    const std::size_t sample_bytes = insitu::scalar_size_bytes(arguments.type);
    std::uint64_t samples = 1;
    for (std::int64_t n : arguments.dims) {
        if (samples > std::numeric_limits<std::uint64_t>::max() / sample_bytes / n) {
            insitu::fail<insitu::InvalidArgument>("--dims ", arguments.dims[0], ",",
                                                  arguments.dims[1], ",", arguments.dims[2],
                                                  ": the volume size overflows 64 bits");
        }
        samples *= static_cast<std::uint64_t>(n);
    }
    const std::uint64_t expected_bytes = samples * sample_bytes;

    std::error_code error;
    const std::uint64_t actual_bytes = std::filesystem::file_size(arguments.raw_path, error);
    if (error) {
        insitu::fail<insitu::IoError>("--raw \"", arguments.raw_path, "\": ", error.message());
    }
    if (actual_bytes != expected_bytes) {
        insitu::fail<insitu::InvalidArgument>(
            "--raw \"", arguments.raw_path, "\" has ", actual_bytes, " bytes but --dims ",
            arguments.dims[0], ",", arguments.dims[1], ",", arguments.dims[2], " --type ",
            insitu::to_string(arguments.type), " needs ", expected_bytes, " (", samples, " x ",
            sample_bytes, " bytes)");
    }

    std::vector<std::byte> bytes(expected_bytes);
    std::ifstream in(arguments.raw_path, std::ios::binary);
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!in) {
        insitu::fail<insitu::IoError>("--raw \"", arguments.raw_path, "\": read failed after ",
                                      in.gcount(), " of ", expected_bytes, " bytes");
    }
    // Raw files are little-endian by convention; swap each sample on a big-endian host.
    if (sample_bytes > 1 && !host_is_little_endian()) {
        for (std::byte* sample = bytes.data(); sample != bytes.data() + bytes.size();
             sample += sample_bytes) {
            std::reverse(sample, sample + sample_bytes);
        }
    }
    return bytes;
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
        .count();
}

int run(const Arguments& arguments) {
    // Everything cheap is checked before the volume is read and OpenCL is started.
    insitu::validate(arguments.settings);
    const insitu::TransferFunction tf = insitu::TransferFunction::from_json_file(arguments.tf_path);

    const std::vector<std::byte> raw = read_raw_volume(arguments);
    insitu::Field field(std::filesystem::path(arguments.raw_path).stem().string(), raw.data(),
                        arguments.type, arguments.dims);
    field.set_spacing(arguments.spacing_world).set_origin(arguments.origin_world);
    const insitu::Camera camera = insitu::Camera::orbit(arguments.view, field.bounds());

    insitu::VolumeRenderer renderer;
    const auto upload_start = std::chrono::steady_clock::now();
    renderer.upload(field);
    const double upload_ms = milliseconds_since(upload_start);
    const auto render_start = std::chrono::steady_clock::now();
    const insitu::Rendering rendering = renderer.render(camera, tf, arguments.settings);
    const double render_ms = milliseconds_since(render_start);

    insitu::write_image(arguments.out_path, rendering.rgba);
    if (!arguments.depth_out_path.empty()) {
        insitu::write_exr(arguments.depth_out_path, rendering.depth, {"Z"});
    }

    std::ostringstream summary;
    summary.setf(std::ios::fixed);
    summary.precision(1);
    summary << kProgram << ": " << camera.width() << "x" << camera.height() << " rendered in "
            << render_ms << " ms (upload " << upload_ms << " ms) -> " << arguments.out_path;
    if (!arguments.depth_out_path.empty()) summary << ", depth -> " << arguments.depth_out_path;
    std::cout << summary.str() << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    return insitu::cli::run_command(kProgram, insitu::cli::program_arguments(argc, argv),
                                    command_help(),
                                    [&] { return run(parse_arguments(argc, argv)); });
}
