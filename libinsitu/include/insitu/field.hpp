#pragma once
// Field: a non-owning view of one scalar array of a simulation on a uniform grid.
// Nothing is copied when a Field is made; the simulation keeps ownership of its memory and
// the view must not outlive it. Samples are x fastest. What the origin means depends on the
// centring (set_centering), the one place it is defined:
//  - node (default): sample (i, j, k) of the interior is the value at the grid node
//    origin + (i, j, k) * spacing, so the origin is the first interior sample;
//  - cell: sample (i, j, k) is the value of the cell [origin + (i, j, k) * spacing,
//    origin + (i + 1, j + 1, k + 1) * spacing], taken at its centre; the origin is the low corner
//    of the first interior cell (the corner of the simulation's domain, or of its block).
// Either way the renderers sample at first_sample() + (i, j, k) * spacing and march the box
// through the samples, bounds(); trilinear interpolation needs no value beyond it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <iosfwd>
#include <string>
#include <vector>

namespace insitu {

enum class ScalarType { uint8, uint16, int16, float32, float64 };

/// Bytes per sample of a ScalarType.
std::size_t scalar_size_bytes(ScalarType type);
/// "uint8", "uint16", "int16", "float32", "float64".
std::string to_string(ScalarType type);
/// Inverse of to_string; throws InvalidArgument naming the unknown text.
ScalarType parse_scalar_type(const std::string& text);

using Index3 = std::array<std::int64_t, 3>;

/// a * b and a + b, or InvalidArgument "`what`: a * b overflows 64-bit integers". Every size,
/// offset and stride product made of values a simulation or a file supplies goes through these,
/// so that none can wrap into a small number that defeats a later bound (issue 19).
std::int64_t checked_multiply(std::int64_t a, std::int64_t b, const std::string& what);
std::int64_t checked_add(std::int64_t a, std::int64_t b, const std::string& what);

/// Finite value range of a field and how many samples were NaN or +-Inf (treated as empty).
struct ValueRange {
    double min = 0.0;
    double max = 0.0;
    std::int64_t finite_count = 0;
    std::int64_t nonfinite_count = 0;
    bool empty() const { return finite_count == 0; }
};
std::ostream& operator<<(std::ostream& out, const ValueRange& range);

/// Axis-aligned world-space box.
struct Bounds {
    glm::dvec3 lower{0.0};
    glm::dvec3 upper{0.0};
    glm::dvec3 center() const { return 0.5 * (lower + upper); }
    /// Radius of the bounding sphere around center().
    double radius() const;
};
std::ostream& operator<<(std::ostream& out, const Bounds& bounds);

/// Where a field's values sit on its grid (see the comment at the top of this file).
enum class Centering { node, cell };
/// "node", "cell".
std::string to_string(Centering centering);
/// Inverse of to_string; throws InvalidArgument naming the unknown text.
Centering parse_centering(const std::string& text);

class Field {
public:
    /// A view of a contiguous x-fastest array of `allocated_dims` samples.
    /// Throws InvalidArgument for a null pointer, a non-positive dimension, or dims whose extent
    /// in bytes does not fit in 64-bit integers.
    Field(std::string name, const void* data, ScalarType type, Index3 allocated_dims);

    /// World position of the first interior node (node centring) or of the low corner of the
    /// first interior cell (cell centring), world units, finite. Default (0, 0, 0).
    Field& set_origin(glm::dvec3 origin_world);
    /// Node (default) or cell centring: what the origin means.
    Field& set_centering(Centering centering);
    /// Distance between samples along each axis (world units, > 0 and finite). Default (1, 1, 1).
    Field& set_spacing(glm::dvec3 spacing_world);
    /// Ghost layers to skip on the low and high side of each axis (samples, >= 0).
    /// The interior is allocated_dims - low - high and must keep at least one sample per axis.
    Field& set_ghost_layers(Index3 low, Index3 high);
    /// Same number of ghost layers on every side.
    Field& set_ghost_layers(std::int64_t layers);
    /// Distance between neighbours along x, y, z in samples (not bytes), for arrays that are
    /// padded, transposed or interleaved. Default: x-fastest contiguous, {1, nx, nx*ny}.
    /// Strides must be positive, and the last allocated sample's offset in bytes must fit in
    /// 64-bit integers; whether the extent addresses memory twice is left to the simulation.
    Field& set_strides(Index3 strides_samples);

    const std::string& name() const { return name_; }
    ScalarType type() const { return type_; }
    const void* data() const { return data_; }
    Index3 allocated_dims() const { return allocated_dims_; }
    /// Samples per axis after the ghost layers are skipped.
    Index3 dims() const;
    std::int64_t sample_count() const;
    /// As set: the first node or the first cell's low corner (see centering()).
    glm::dvec3 origin() const { return origin_; }
    glm::dvec3 spacing() const { return spacing_; }
    Centering centering() const { return centering_; }
    /// World position of interior sample (0, 0, 0): the origin, or the first cell's centre.
    glm::dvec3 first_sample() const;
    Index3 ghost_low() const { return ghost_low_; }
    Index3 ghost_high() const { return ghost_high_; }
    Index3 strides() const { return strides_; }
    /// World box spanned by the interior samples (through the cell centres for cell centring):
    /// the box the renderers march.
    Bounds bounds() const;

    /// Interior sample (i, j, k) as double, read through the type, ghosts and strides.
    double value(std::int64_t i, std::int64_t j, std::int64_t k) const;

    /// Scans the interior once: finite min/max and the number of NaN/Inf samples.
    ValueRange value_range() const;

    /// Packs the interior into `out` as x-fastest float32 (resized to sample_count()).
    /// Non-finite samples become NaN: renderers treat NaN as empty space.
    /// Returns the value range found on the way, so callers need not scan twice.
    ValueRange copy_interior_as_float(std::vector<float>& out) const;

private:
    /// Throws unless the offset in bytes of the last allocated sample, through `strides`, fits in
    /// int64: then every offset and count below it does too, and no index product can wrap.
    void check_extent(const Index3& strides) const;
    std::int64_t offset_of(std::int64_t i, std::int64_t j, std::int64_t k) const;

    std::string name_;
    const void* data_;
    ScalarType type_;
    Index3 allocated_dims_;
    glm::dvec3 origin_{0.0};
    glm::dvec3 spacing_{1.0};
    Centering centering_ = Centering::node;
    Index3 ghost_low_{0, 0, 0};
    Index3 ghost_high_{0, 0, 0};
    Index3 strides_;
};

std::ostream& operator<<(std::ostream& out, const Field& field);

/// Joins the blocks (tiles) of one field that a rank owns into one node-centred float32 Field
/// viewing `storage` (resized), on the grid the blocks share. They must have the same name,
/// spacing (to 1e-9 relative) and centring, first samples a whole number of samples apart (to
/// 1e-6 samples), and their interiors must together cover the box around them; samples two
/// blocks share (node-centred tiles meeting at a face) take the later block's value. Otherwise
/// InvalidArgument naming the blocks by their position in `blocks` and the offending value.
/// A single block is copied too: callers that can use it directly should.
Field join_blocks(const std::vector<const Field*>& blocks, std::vector<float>& storage);

}  // namespace insitu
