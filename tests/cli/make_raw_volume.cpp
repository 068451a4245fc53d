// make_raw_volume: writes a small raw volume for the insitu-render CLI tests.
//
//   make_raw_volume OUT.raw NX,NY,NZ TYPE
//
// The volume is a radial ramp, value = max(0, 1 - r / R) with r the distance from the grid centre
// and R half the smallest extent (voxel units), so it is 1 in the middle and 0 at the faces.
// Float types store that value; integer types scale it to their largest value (uint8: 255,
// uint16: 65535, int16: 32767). Samples are written x fastest and little-endian, as the CLI reads
// them.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <iostream>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/field.hpp"

namespace {

/// Appends `value` as little-endian bytes, whatever the host's byte order.
template <typename T>
void append_little_endian(std::vector<unsigned char>& out, T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    const std::uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    if (first != 1) std::reverse(bytes, bytes + sizeof(T));
    out.insert(out.end(), bytes, bytes + sizeof(T));
}

void append_sample(std::vector<unsigned char>& out, insitu::ScalarType type, double unit_value) {
    switch (type) {
        case insitu::ScalarType::float32:
            return append_little_endian(out, static_cast<float>(unit_value));
        case insitu::ScalarType::float64:
            return append_little_endian(out, unit_value);
        case insitu::ScalarType::uint8:
            return append_little_endian(out,
                                        static_cast<std::uint8_t>(std::lround(255 * unit_value)));
        case insitu::ScalarType::uint16:
            return append_little_endian(
                out, static_cast<std::uint16_t>(std::lround(65535 * unit_value)));
        case insitu::ScalarType::int16:
            return append_little_endian(out,
                                        static_cast<std::int16_t>(std::lround(32767 * unit_value)));
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::cerr << "usage: make_raw_volume OUT.raw NX,NY,NZ TYPE\n";
        return 2;
    }
    try {
        long nx = 0, ny = 0, nz = 0;
        if (std::sscanf(argv[2], "%ld,%ld,%ld", &nx, &ny, &nz) != 3 || nx < 1 || ny < 1 || nz < 1) {
            insitu::fail<insitu::InvalidArgument>("dims \"", argv[2], "\" (expected NX,NY,NZ)");
        }
        const insitu::ScalarType type = insitu::parse_scalar_type(argv[3]);

        const double cx = 0.5 * static_cast<double>(nx - 1);
        const double cy = 0.5 * static_cast<double>(ny - 1);
        const double cz = 0.5 * static_cast<double>(nz - 1);
        const double radius_voxels = std::max(0.5, std::min({cx, cy, cz}));
        std::vector<unsigned char> bytes;
        bytes.reserve(static_cast<std::size_t>(nx * ny * nz) * insitu::scalar_size_bytes(type));
        for (long k = 0; k < nz; ++k) {
            for (long j = 0; j < ny; ++j) {
                for (long i = 0; i < nx; ++i) {
                    const glm::dvec3 offset(static_cast<double>(i) - cx,
                                            static_cast<double>(j) - cy,
                                            static_cast<double>(k) - cz);
                    const double r = glm::length(offset);
                    append_sample(bytes, type, std::max(0.0, 1.0 - r / radius_voxels));
                }
            }
        }
        // The tests start from a clean output folder; make it.
        const std::filesystem::path path(argv[1]);
        if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()),
                  static_cast<std::streamsize>(bytes.size()));
        if (!out) insitu::fail<insitu::IoError>("cannot write \"", argv[1], "\"");
    } catch (const std::exception& error) {  // insitu::Error or std::filesystem::filesystem_error
        std::cerr << "make_raw_volume: " << error.what() << "\n";
        return 2;
    }
    return 0;
}
