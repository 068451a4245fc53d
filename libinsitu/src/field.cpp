#include "insitu/field.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <limits>
#include <ostream>

#include "insitu/error.hpp"

namespace insitu {

std::size_t scalar_size_bytes(ScalarType type) {
    switch (type) {
        case ScalarType::uint8:
            return 1;
        case ScalarType::uint16:
            return 2;
        case ScalarType::int16:
            return 2;
        case ScalarType::float32:
            return 4;
        case ScalarType::float64:
            return 8;
    }
    fail<InvalidArgument>("unknown ScalarType ", static_cast<int>(type));
}

std::string to_string(ScalarType type) {
    switch (type) {
        case ScalarType::uint8:
            return "uint8";
        case ScalarType::uint16:
            return "uint16";
        case ScalarType::int16:
            return "int16";
        case ScalarType::float32:
            return "float32";
        case ScalarType::float64:
            return "float64";
    }
    fail<InvalidArgument>("unknown ScalarType ", static_cast<int>(type));
}

ScalarType parse_scalar_type(const std::string& text) {
    for (ScalarType type : {ScalarType::uint8, ScalarType::uint16, ScalarType::int16,
                            ScalarType::float32, ScalarType::float64}) {
        if (text == to_string(type)) return type;
    }
    fail<InvalidArgument>("unsupported scalar type \"", text,
                          "\" (expected uint8, uint16, int16, float32 or float64)");
}

std::string to_string(Centering centering) {
    return centering == Centering::cell ? "cell" : "node";
}

Centering parse_centering(const std::string& text) {
    if (text == "node") return Centering::node;
    if (text == "cell") return Centering::cell;
    fail<InvalidArgument>("unknown centring \"", text, "\" (expected \"node\" or \"cell\")");
}

std::ostream& operator<<(std::ostream& out, const ValueRange& range) {
    return out << "ValueRange{min=" << range.min << ", max=" << range.max
               << ", finite=" << range.finite_count << ", nonfinite=" << range.nonfinite_count
               << "}";
}

double Bounds::radius() const {
    return 0.5 * glm::length(upper - lower);
}

std::ostream& operator<<(std::ostream& out, const Bounds& bounds) {
    return out << "Bounds{(" << bounds.lower.x << ", " << bounds.lower.y << ", " << bounds.lower.z
               << ") - (" << bounds.upper.x << ", " << bounds.upper.y << ", " << bounds.upper.z
               << ")}";
}

std::int64_t checked_multiply(std::int64_t a, std::int64_t b, const std::string& what) {
    std::int64_t product = 0;
    if (__builtin_mul_overflow(a, b, &product)) {
        fail<InvalidArgument>(what, ": ", a, " * ", b, " overflows 64-bit integers");
    }
    return product;
}

std::int64_t checked_add(std::int64_t a, std::int64_t b, const std::string& what) {
    std::int64_t sum = 0;
    if (__builtin_add_overflow(a, b, &sum)) {
        fail<InvalidArgument>(what, ": ", a, " + ", b, " overflows 64-bit integers");
    }
    return sum;
}

namespace {
const char* axis_name(int axis) {
    return axis == 0 ? "x" : axis == 1 ? "y" : "z";
}

std::string triple(const Index3& values) {
    return detail::concat("(", values[0], ", ", values[1], ", ", values[2], ")");
}
}  // namespace

Field::Field(std::string name, const void* data, ScalarType type, Index3 allocated_dims)
    : name_(std::move(name)), data_(data), type_(type), allocated_dims_(allocated_dims) {
    if (data == nullptr) fail<InvalidArgument>("field \"", name_, "\": data pointer is null");
    scalar_size_bytes(type);  // rejects values outside the enum
    for (int axis = 0; axis < 3; ++axis) {
        if (allocated_dims[axis] < 1) {
            fail<InvalidArgument>("field \"", name_, "\": dims.", axis_name(axis), " = ",
                                  allocated_dims[axis], " (must be >= 1)");
        }
    }
    // Unchecked, dims of 2^31 x 2^31 x 4 wrapped to 0 samples, passed every size bound and
    // crashed the first execute.
    const std::string what = "field \"" + name_ + "\": dims " + triple(allocated_dims);
    const std::int64_t plane = checked_multiply(allocated_dims[0], allocated_dims[1], what);
    const Index3 strides{1, allocated_dims[0], plane};
    check_extent(strides);
    strides_ = strides;
}

void Field::check_extent(const Index3& strides) const {
    const std::string what = "field \"" + name_ + "\": dims " + triple(allocated_dims_) +
                             " with strides " + triple(strides);
    std::int64_t last_offset = 0;
    for (int axis = 0; axis < 3; ++axis) {
        last_offset = checked_add(
            last_offset, checked_multiply(allocated_dims_[axis] - 1, strides[axis], what), what);
    }
    const auto sample_bytes = static_cast<std::int64_t>(scalar_size_bytes(type_));
    checked_multiply(checked_add(last_offset, 1, what), sample_bytes, what + ", in bytes");
}

Field& Field::set_origin(glm::dvec3 origin_world) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!std::isfinite(origin_world[axis])) {
            fail<InvalidArgument>("field \"", name_, "\": origin.", axis_name(axis), " = ",
                                  origin_world[axis], " (must be finite)");
        }
    }
    origin_ = origin_world;
    return *this;
}

Field& Field::set_centering(Centering centering) {
    centering_ = centering;
    return *this;
}

glm::dvec3 Field::first_sample() const {
    // A cell's value is taken at its centre, half a spacing inside its low corner.
    return centering_ == Centering::cell ? origin_ + 0.5 * spacing_ : origin_;
}

Field& Field::set_spacing(glm::dvec3 spacing_world) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!(spacing_world[axis] > 0.0) || !std::isfinite(spacing_world[axis])) {
            fail<InvalidArgument>("field \"", name_, "\": spacing.", axis_name(axis), " = ",
                                  spacing_world[axis], " (must be finite and > 0)");
        }
    }
    spacing_ = spacing_world;
    return *this;
}

Field& Field::set_ghost_layers(Index3 low, Index3 high) {
    for (int axis = 0; axis < 3; ++axis) {
        if (low[axis] < 0 || high[axis] < 0) {
            fail<InvalidArgument>("field \"", name_, "\": ghost layers on ", axis_name(axis),
                                  " = (", low[axis], ", ", high[axis], ") (must be >= 0)");
        }
        // Checked: ghost layers of INT64_MAX on both sides used to wrap into a large interior.
        const std::int64_t ghosts = checked_add(
            low[axis], high[axis], "field \"" + name_ + "\": ghost layers on " + axis_name(axis));
        if (allocated_dims_[axis] - ghosts < 1) {
            fail<InvalidArgument>("field \"", name_, "\": ghost layers on ", axis_name(axis),
                                  " = (", low[axis], ", ", high[axis],
                                  ") leave no interior of dims.", axis_name(axis), " = ",
                                  allocated_dims_[axis]);
        }
    }
    ghost_low_ = low;
    ghost_high_ = high;
    return *this;
}

Field& Field::set_ghost_layers(std::int64_t layers) {
    return set_ghost_layers({layers, layers, layers}, {layers, layers, layers});
}

Field& Field::set_strides(Index3 strides_samples) {
    for (int axis = 0; axis < 3; ++axis) {
        if (strides_samples[axis] < 1) {
            fail<InvalidArgument>("field \"", name_, "\": strides.", axis_name(axis), " = ",
                                  strides_samples[axis], " (must be >= 1 sample)");
        }
    }
    check_extent(strides_samples);
    strides_ = strides_samples;
    return *this;
}

Index3 Field::dims() const {
    return {allocated_dims_[0] - ghost_low_[0] - ghost_high_[0],
            allocated_dims_[1] - ghost_low_[1] - ghost_high_[1],
            allocated_dims_[2] - ghost_low_[2] - ghost_high_[2]};
}

std::int64_t Field::sample_count() const {
    // Cannot overflow: the interior is within the allocation, whose extent the constructor
    // checked.
    const Index3 d = dims();
    return d[0] * d[1] * d[2];
}

Bounds Field::bounds() const {
    const Index3 d = dims();
    const glm::dvec3 extent(static_cast<double>(d[0] - 1), static_cast<double>(d[1] - 1),
                            static_cast<double>(d[2] - 1));
    return Bounds{first_sample(), first_sample() + extent * spacing_};
}

std::int64_t Field::offset_of(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return (i + ghost_low_[0]) * strides_[0] + (j + ghost_low_[1]) * strides_[1] +
           (k + ghost_low_[2]) * strides_[2];
}

namespace {
template <typename T>
double load(const void* data, std::int64_t offset) {
    T value;
    std::memcpy(&value, static_cast<const unsigned char*>(data) + offset * sizeof(T), sizeof(T));
    return static_cast<double>(value);
}

double load_as_double(const void* data, ScalarType type, std::int64_t offset) {
    switch (type) {
        case ScalarType::uint8:
            return load<std::uint8_t>(data, offset);
        case ScalarType::uint16:
            return load<std::uint16_t>(data, offset);
        case ScalarType::int16:
            return load<std::int16_t>(data, offset);
        case ScalarType::float32:
            return load<float>(data, offset);
        case ScalarType::float64:
            return load<double>(data, offset);
    }
    return 0.0;
}

// Walks the interior in x-fastest order, handing each sample (as T) to `visit`. The x loop is
// kept free of type dispatch so the scan runs at memory speed.
template <typename T, typename Visit>
void for_each_interior(const Field& field, Visit&& visit) {
    const Index3 d = field.dims();
    const Index3 s = field.strides();
    const Index3 g = field.ghost_low();
    const T* base = static_cast<const T*>(field.data());
    for (std::int64_t k = 0; k < d[2]; ++k) {
        for (std::int64_t j = 0; j < d[1]; ++j) {
            const T* row = base + (k + g[2]) * s[2] + (j + g[1]) * s[1] + g[0] * s[0];
            for (std::int64_t i = 0; i < d[0]; ++i) visit(row[i * s[0]]);
        }
    }
}

template <typename Visit>
void dispatch_interior(const Field& field, Visit&& visit) {
    switch (field.type()) {
        case ScalarType::uint8:
            for_each_interior<std::uint8_t>(field, visit);
            break;
        case ScalarType::uint16:
            for_each_interior<std::uint16_t>(field, visit);
            break;
        case ScalarType::int16:
            for_each_interior<std::int16_t>(field, visit);
            break;
        case ScalarType::float32:
            for_each_interior<float>(field, visit);
            break;
        case ScalarType::float64:
            for_each_interior<double>(field, visit);
            break;
    }
}

struct RangeAccumulator {
    double min = std::numeric_limits<double>::infinity();
    double max = -std::numeric_limits<double>::infinity();
    std::int64_t finite = 0;
    std::int64_t nonfinite = 0;
    bool add(double value) {
        if (!std::isfinite(value)) {
            ++nonfinite;
            return false;
        }
        min = std::min(min, value);
        max = std::max(max, value);
        ++finite;
        return true;
    }
    ValueRange result() const {
        ValueRange range;
        range.finite_count = finite;
        range.nonfinite_count = nonfinite;
        if (finite > 0) {
            range.min = min;
            range.max = max;
        }
        return range;
    }
};
}  // namespace

double Field::value(std::int64_t i, std::int64_t j, std::int64_t k) const {
    const Index3 d = dims();
    if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2]) {
        fail<InvalidArgument>("field \"", name_, "\": sample (", i, ", ", j, ", ", k,
                              ") outside dims (", d[0], ", ", d[1], ", ", d[2], ")");
    }
    return load_as_double(data_, type_, offset_of(i, j, k));
}

ValueRange Field::value_range() const {
    RangeAccumulator accumulator;
    dispatch_interior(*this, [&](auto sample) { accumulator.add(static_cast<double>(sample)); });
    return accumulator.result();
}

ValueRange Field::copy_interior_as_float(std::vector<float>& out) const {
    out.resize(static_cast<std::size_t>(sample_count()));
    RangeAccumulator accumulator;
    float* cursor = out.data();
    dispatch_interior(*this, [&](auto sample) {
        const double value = static_cast<double>(sample);
        *cursor++ = accumulator.add(value) ? static_cast<float>(value)
                                           : std::numeric_limits<float>::quiet_NaN();
    });
    return accumulator.result();
}

Field join_blocks(const std::vector<const Field*>& blocks, std::vector<float>& storage) {
    if (blocks.empty()) fail<InvalidArgument>("join_blocks: no blocks");
    const Field& first = *blocks.front();
    const std::string& name = first.name();
    const auto where = [&](std::size_t b) {
        return "field \"" + name + "\" block " + std::to_string(b);
    };
    // Each block's offset on the shared grid, in samples from the lowest first sample.
    glm::dvec3 lower = first.first_sample();
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        const Field& block = *blocks[b];
        if (block.name() != name) {
            fail<InvalidArgument>(where(b), " is named \"", block.name(), "\"");
        }
        if (block.centering() != first.centering()) {
            fail<InvalidArgument>(where(b), " is ", to_string(block.centering()),
                                  "-centred, block 0 ", to_string(first.centering()),
                                  "-centred (blocks of a field share their centring)");
        }
        for (int axis = 0; axis < 3; ++axis) {
            const double a = block.spacing()[axis];
            const double b0 = first.spacing()[axis];
            if (std::abs(a - b0) > 1e-9 * std::max(std::abs(a), std::abs(b0))) {
                fail<InvalidArgument>(where(b), ": spacing.", axis_name(axis), " = ", a,
                                      ", block 0 has ", b0, " (blocks of a field share a grid)");
            }
        }
        lower = glm::min(lower, block.first_sample());
    }
    const glm::dvec3 spacing = first.spacing();
    std::vector<Index3> offsets;
    Index3 dims{0, 0, 0};
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        const Field& block = *blocks[b];
        Index3 offset{};
        for (int axis = 0; axis < 3; ++axis) {
            const double samples = (block.first_sample()[axis] - lower[axis]) / spacing[axis];
            const double whole = std::round(samples);
            if (std::abs(samples - whole) > 1e-6) {
                fail<InvalidArgument>(where(b), ": origin.", axis_name(axis), " = ",
                                      block.origin()[axis], " is ", samples,
                                      " samples from the lowest block's, not a whole number "
                                      "(blocks of a field share a grid)");
            }
            offset[axis] = static_cast<std::int64_t>(whole);
            dims[axis] = std::max(
                dims[axis], checked_add(offset[axis], block.dims()[axis], where(b) + ": extent"));
        }
        offsets.push_back(offset);
    }
    const std::int64_t count = checked_multiply(checked_multiply(dims[0], dims[1], "joined blocks"),
                                                dims[2], "joined blocks of field \"" + name + "\"");
    storage.assign(static_cast<std::size_t>(count), std::numeric_limits<float>::quiet_NaN());
    std::vector<bool> covered(static_cast<std::size_t>(count), false);
    std::vector<float> interior;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        blocks[b]->copy_interior_as_float(interior);
        const Index3 d = blocks[b]->dims();
        const Index3& o = offsets[b];
        const float* source = interior.data();
        for (std::int64_t k = 0; k < d[2]; ++k) {
            for (std::int64_t j = 0; j < d[1]; ++j) {
                const std::size_t row =
                    static_cast<std::size_t>(((k + o[2]) * dims[1] + (j + o[1])) * dims[0] + o[0]);
                std::copy(source, source + d[0],
                          storage.begin() + static_cast<std::ptrdiff_t>(row));
                std::fill(covered.begin() + static_cast<std::ptrdiff_t>(row),
                          covered.begin() + static_cast<std::ptrdiff_t>(row) + d[0], true);
                source += d[0];
            }
        }
    }
    const auto gap = std::find(covered.begin(), covered.end(), false);
    if (gap != covered.end()) {
        const auto index = static_cast<std::int64_t>(gap - covered.begin());
        const Index3 at{index % dims[0], (index / dims[0]) % dims[1], index / (dims[0] * dims[1])};
        const glm::dvec3 world = lower + glm::dvec3(at[0], at[1], at[2]) * spacing;
        fail<InvalidArgument>("field \"", name, "\": its ", blocks.size(),
                              " blocks leave a gap: no block holds the sample at (", world.x, ", ",
                              world.y, ", ", world.z, ") (sample (", at[0], ", ", at[1], ", ",
                              at[2], ") of the box around them); blocks must cover a box");
    }
    Field joined(name, storage.data(), ScalarType::float32, dims);
    joined.set_origin(lower).set_spacing(spacing);
    return joined;
}

std::ostream& operator<<(std::ostream& out, const Field& field) {
    const Index3 d = field.dims();
    return out << "Field{\"" << field.name() << "\", " << to_string(field.type()) << ", dims=("
               << d[0] << ", " << d[1] << ", " << d[2] << "), origin=(" << field.origin().x << ", "
               << field.origin().y << ", " << field.origin().z << "), spacing=("
               << field.spacing().x << ", " << field.spacing().y << ", " << field.spacing().z
               << "), " << to_string(field.centering()) << "}";
}

}  // namespace insitu
