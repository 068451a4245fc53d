#include "insitu/raw_reader.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <system_error>

#include "insitu/error.hpp"

namespace insitu::capture {

namespace {

struct RawTypeInfo {
    RawType type;
    const char* name;
    std::size_t bytes;
};

constexpr std::array<RawTypeInfo, 10> kRawTypes = {{
    {RawType::uint8, "uint8", 1},
    {RawType::int8, "int8", 1},
    {RawType::uint16, "uint16", 2},
    {RawType::int16, "int16", 2},
    {RawType::uint32, "uint32", 4},
    {RawType::int32, "int32", 4},
    {RawType::uint64, "uint64", 8},
    {RawType::int64, "int64", 8},
    {RawType::float32, "float32", 4},
    {RawType::float64, "float64", 8},
}};

const RawTypeInfo& info(RawType type) {
    return *std::find_if(kRawTypes.begin(), kRawTypes.end(),
                         [&](const RawTypeInfo& i) { return i.type == type; });
}

/// The Field type that views samples of `type` in place, if any.
bool field_type_of(RawType type, ScalarType& field_type) {
    switch (type) {
        case RawType::uint8:
            field_type = ScalarType::uint8;
            return true;
        case RawType::uint16:
            field_type = ScalarType::uint16;
            return true;
        case RawType::int16:
            field_type = ScalarType::int16;
            return true;
        case RawType::float32:
            field_type = ScalarType::float32;
            return true;
        case RawType::float64:
            field_type = ScalarType::float64;
            return true;
        default:
            return false;
    }
}

bool host_is_little_endian() {
    const std::uint16_t probe = 1;
    unsigned char first_byte = 0;
    std::memcpy(&first_byte, &probe, 1);
    return first_byte == 1;
}

template <typename T>
void convert_to_float(const unsigned char* bytes, std::size_t count, float* out) {
    for (std::size_t i = 0; i < count; ++i) {
        T value;
        std::memcpy(&value, bytes + i * sizeof(T), sizeof(T));
        out[i] = static_cast<float>(value);
    }
}

void convert_to_float(RawType type, const unsigned char* bytes, std::size_t count, float* out) {
    switch (type) {
        case RawType::int8:
            return convert_to_float<std::int8_t>(bytes, count, out);
        case RawType::uint32:
            return convert_to_float<std::uint32_t>(bytes, count, out);
        case RawType::int32:
            return convert_to_float<std::int32_t>(bytes, count, out);
        case RawType::uint64:
            return convert_to_float<std::uint64_t>(bytes, count, out);
        case RawType::int64:
            return convert_to_float<std::int64_t>(bytes, count, out);
        default:
            fail<InvalidArgument>("raw type ", to_string(type), " needs no conversion");
    }
}

}  // namespace

std::string to_string(RawType type) {
    return info(type).name;
}

std::size_t raw_size_bytes(RawType type) {
    return info(type).bytes;
}

RawType parse_raw_type(const std::string& text) {
    for (const RawTypeInfo& i : kRawTypes) {
        if (text == i.name) return i.type;
    }
    std::string names;
    for (const RawTypeInfo& i : kRawTypes)
        names += (names.empty() ? "" : ", ") + std::string(i.name);
    fail<InvalidArgument>("unsupported raw type \"", text, "\" (", names, ")");
}

Field RawVolume::field(const std::string& name) const {
    Field field(name, storage_.data(), field_type_, options_.dims);
    field.set_origin(options_.origin_world).set_spacing(options_.spacing_world);
    return field;
}

RawVolume read_raw(const std::string& path, const RawOptions& options) {
    const auto sample_bytes = static_cast<std::int64_t>(raw_size_bytes(options.type));
    const std::string dims_text = "\"" + path + "\": raw dims " + std::to_string(options.dims[0]) +
                                  "," + std::to_string(options.dims[1]) + "," +
                                  std::to_string(options.dims[2]);
    std::int64_t samples = 1;
    for (int axis = 0; axis < 3; ++axis) {
        if (options.dims[axis] < 1) {
            fail<InvalidArgument>(dims_text, " (every dimension must be positive)");
        }
        samples = checked_multiply(samples, options.dims[axis], dims_text);
    }
    // In int64, like the Field that views the samples.
    const std::int64_t expected_bytes =
        checked_multiply(samples, sample_bytes, dims_text + ", in bytes");

    std::error_code error;
    const std::uint64_t actual_bytes = std::filesystem::file_size(path, error);
    if (error) fail<IoError>("\"", path, "\": ", error.message());
    if (actual_bytes != static_cast<std::uint64_t>(expected_bytes)) {
        fail<InvalidArgument>("\"", path, "\" has ", actual_bytes, " bytes but raw dims ",
                              options.dims[0], ",", options.dims[1], ",", options.dims[2], " ",
                              to_string(options.type), " need ", expected_bytes, " (", samples,
                              " x ", sample_bytes, " bytes)");
    }

    RawVolume volume;
    volume.options_ = options;
    ScalarType field_type = ScalarType::float32;
    volume.converted_ = !field_type_of(options.type, field_type);
    volume.field_type_ = field_type;

    // Read straight into the Field's buffer when no conversion follows, else into a scratch one.
    std::vector<std::byte> scratch;
    std::vector<std::byte>& target = volume.converted_ ? scratch : volume.storage_;
    target.resize(static_cast<std::size_t>(expected_bytes));
    auto* bytes = reinterpret_cast<unsigned char*>(target.data());
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(expected_bytes));
    if (!in) {
        fail<IoError>("\"", path, "\": read failed after ", in.gcount(), " of ", expected_bytes,
                      " bytes");
    }
    if (sample_bytes > 1 && options.big_endian == host_is_little_endian()) {
        for (unsigned char* sample = bytes; sample != bytes + expected_bytes;
             sample += sample_bytes) {
            std::reverse(sample, sample + sample_bytes);
        }
    }
    if (volume.converted_) {
        const std::int64_t converted_bytes = checked_multiply(
            samples, static_cast<std::int64_t>(sizeof(float)), dims_text + ", as float32 bytes");
        volume.storage_.resize(static_cast<std::size_t>(converted_bytes));
        convert_to_float(options.type, bytes, static_cast<std::size_t>(samples),
                         reinterpret_cast<float*>(volume.storage_.data()));
    }
    return volume;
}

}  // namespace insitu::capture
