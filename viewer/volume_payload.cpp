#include "volume_payload.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <vector>

#include "insitu/core/check.hpp"
#include "insitu/error.hpp"
#include "payload_header.hpp"

namespace insitu::viewer {
namespace {

using nlohmann::json;

json vec3(const glm::dvec3& v) {
    return json::array({v.x, v.y, v.z});
}

struct FiniteRange {
    double lo = 0.0;
    double hi = 0.0;
    std::int64_t nonfinite = 0;
};

FiniteRange finite_range(const std::vector<float>& values) {
    FiniteRange range;
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (const float v : values) {
        if (!std::isfinite(v)) {
            ++range.nonfinite;
            continue;
        }
        lo = std::min(lo, static_cast<double>(v));
        hi = std::max(hi, static_cast<double>(v));
    }
    if (lo <= hi) {
        range.lo = lo;
        range.hi = hi;
    }
    return range;
}

std::vector<std::uint16_t> codes_of(const std::vector<float>& values, const FiniteRange& range,
                                    int levels) {
    std::vector<std::uint16_t> codes(values.size());
    const double span = range.hi - range.lo;
    const double scale = span > 0.0 ? levels / span : 0.0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        const float v = values[i];
        if (!std::isfinite(v)) {
            codes[i] = kVolumeNanCode;
            continue;
        }
        const long code = std::lround((static_cast<double>(v) - range.lo) * scale);
        codes[i] = static_cast<std::uint16_t>(std::clamp(code, 0L, static_cast<long>(levels)));
    }
    return codes;
}

/// The residual planes (low bytes, then high bytes) of `codes` after the Lorenzo predictor, as
/// volume_payload.hpp writes it out; appended to `out`.
void append_residuals(std::string& out, const std::vector<std::uint16_t>& codes,
                      const Index3& dims) {
    const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
    const std::int64_t sy = nx, sz = nx * ny;
    const std::size_t count = codes.size();
    const std::size_t at = out.size();
    out.resize(at + 2 * count);
    char* low = &out[at];
    char* high = low + count;
    const auto c = [&](std::int64_t i) { return static_cast<std::uint32_t>(codes[i]); };
    for (std::int64_t k = 0; k < nz; ++k) {
        for (std::int64_t j = 0; j < ny; ++j) {
            for (std::int64_t i = 0; i < nx; ++i) {
                const std::int64_t p = k * sz + j * sy + i;
                const bool x = i > 0, y = j > 0, z = k > 0;
                // Unsigned arithmetic wraps modulo 2^32, so modulo 2^16 it is exact.
                std::uint32_t predicted = 0;
                if (x) predicted += c(p - 1);
                if (y) predicted += c(p - sy);
                if (z) predicted += c(p - sz);
                if (x && y) predicted -= c(p - 1 - sy);
                if (x && z) predicted -= c(p - 1 - sz);
                if (y && z) predicted -= c(p - sy - sz);
                if (x && y && z) predicted += c(p - 1 - sy - sz);
                const std::uint32_t residual = (c(p) - predicted) & 0xffffu;
                low[p] = static_cast<char>(residual & 0xffu);
                high[p] = static_cast<char>(residual >> 8);
            }
        }
    }
}

}  // namespace

int volume_levels(double range, double tolerance) {
    if (!(range > 0.0) || !(tolerance > 0.0) || !std::isfinite(tolerance)) {
        return kMaxVolumeLevels;
    }
    // Rounding to L levels errs by at most range / (2 L); an eighth of the tolerance needs
    // L >= 4 range / tolerance.
    const double wanted = std::ceil(4.0 * range / tolerance);
    return static_cast<int>(std::clamp(wanted, static_cast<double>(kMinVolumeLevels),
                                       static_cast<double>(kMaxVolumeLevels)));
}

std::string volume_payload(const VolumeGrid& grid, const ArchivedVolume& stored, int view) {
    const Index3& dims = grid.dims;
    if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1 ||
        grid.values.size() != static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]) {
        fail<InvalidArgument>("volume payload: field \"", grid.field, "\" has ", grid.values.size(),
                              " values for ", dims[0], "x", dims[1], "x", dims[2], " samples");
    }
    const FiniteRange range = finite_range(grid.values);
    const int levels = volume_levels(range.hi - range.lo, stored.tolerance);
    const json header{
        {"step", stored.step},
        {"view", view},
        {"field", grid.field},
        {"dims", {dims[0], dims[1], dims[2]}},
        {"origin", vec3(grid.origin)},
        {"spacing", vec3(grid.spacing)},
        {"range", {range.lo, range.hi}},
        {"nonfinite", range.nonfinite},
        {"codes", {{"levels", levels}, {"nan_code", kVolumeNanCode}, {"predictor", "lorenzo"}}},
        {"archive",
         {{"codec", stored.codec},
          {"mode", to_string(stored.mode)},
          {"tolerance", stored.tolerance},
          {"rate", stored.rate},
          {"min", stored.min},
          {"max", stored.max},
          {"bytes", stored.bytes}}}};
    std::string out = payload_opening("insituVF", kVolumePayloadVersion, header);
    const std::size_t data_start = out.size();
    append_residuals(out, codes_of(grid.values, range, levels), dims);
    INSITU_CHECK_EQ(out.size() - data_start, 2 * grid.values.size());
    return out;
}

}  // namespace insitu::viewer
