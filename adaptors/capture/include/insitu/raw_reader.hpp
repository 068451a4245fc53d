#pragma once
// Raw volume files: a bare x-fastest array of samples with no header, described on the side
// (dims, type, byte order, spacing). insitu-capture's raw path and its tests use this.
//
// Types: the five Field types (uint8, uint16, int16, float32, float64) are read into one buffer
// and viewed in place; the others a raw file may hold (int8, uint32, int32, uint64, int64) are
// converted once to float32, which is what the renderer uploads anyway (integers of magnitude up
// to 2^24 exactly). Big-endian files are byte-swapped in the buffer after reading.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/field.hpp"

namespace insitu::capture {

enum class RawType { uint8, int8, uint16, int16, uint32, int32, uint64, int64, float32, float64 };

/// "uint8", "int8", ..., "float64".
std::string to_string(RawType type);
/// Inverse of to_string; throws InvalidArgument naming the text and listing the types.
RawType parse_raw_type(const std::string& text);
std::size_t raw_size_bytes(RawType type);

struct RawOptions {
    Index3 dims{0, 0, 0};  ///< samples per axis (> 0)
    RawType type = RawType::float32;
    glm::dvec3 spacing_world{1.0};  ///< distance between samples, world units
    glm::dvec3 origin_world{0.0};   ///< world position of the first sample
    bool big_endian = false;        ///< the file's byte order (default little-endian)
};

/// A raw file read into memory; field() views that memory.
class RawVolume {
public:
    /// Field named `name` over the samples, with the options' origin and spacing.
    Field field(const std::string& name) const;
    /// Whether the samples were converted to float32 (the file's type has no Field equivalent).
    bool converted() const { return converted_; }
    const RawOptions& options() const { return options_; }

private:
    friend RawVolume read_raw(const std::string& path, const RawOptions& options);

    RawOptions options_;
    ScalarType field_type_ = ScalarType::float32;
    bool converted_ = false;
    /// Samples as field_type_; from operator new, so aligned for every scalar type.
    std::vector<std::byte> storage_;
};

/// Reads `path`. Throws InvalidArgument when a dimension is not positive or the file size is not
/// dims x type size (naming both sizes), IoError when the file cannot be opened or read.
RawVolume read_raw(const std::string& path, const RawOptions& options);

}  // namespace insitu::capture
