#include "parallel/halo_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "insitu/render/volume_renderer.hpp"
#include "parallel/agreement.hpp"

namespace insitu {

namespace {

/// Grid indices [lower, upper) per axis.
struct Box {
    Index3 lower{0, 0, 0};
    Index3 upper{0, 0, 0};
    bool empty() const {
        for (int axis = 0; axis < 3; ++axis) {
            if (upper[axis] <= lower[axis]) return true;
        }
        return false;
    }
};

/// One marched ghost layer's samples that another rank's interior holds.
struct Overlap {
    int holder = 0;
    int owner = 0;
    int axis = 0;
    Box box;
};

/// Every (holder, owner, axis) whose ghost layer meets the owner's interior, in an order every
/// rank computes alike from the shared decomposition.
std::vector<Overlap> overlaps(const Decomposition& grid) {
    std::vector<Overlap> found;
    const int ranks = static_cast<int>(grid.parts.size());
    for (int holder = 0; holder < ranks; ++holder) {
        const Decomposition::Part& h = grid.parts[holder];
        if (!h.present) continue;
        for (int owner = 0; owner < ranks; ++owner) {
            const Decomposition::Part& o = grid.parts[owner];
            if (owner == holder || !o.present) continue;
            for (int axis = 0; axis < 3; ++axis) {
                if (h.marched_ghosts[axis] == 0) continue;
                Box box;
                for (int a = 0; a < 3; ++a) {
                    // The layer: one index along `axis`, the whole marched block across it.
                    const std::int64_t low =
                        a == axis ? h.interior_lower[a] + h.interior_dims[a] : h.interior_lower[a];
                    const std::int64_t high =
                        a == axis ? low + 1
                                  : h.interior_lower[a] + h.interior_dims[a] + h.marched_ghosts[a];
                    box.lower[a] = std::max(low, o.interior_lower[a]);
                    box.upper[a] = std::min(high, o.interior_lower[a] + o.interior_dims[a]);
                }
                if (!box.empty()) found.push_back({holder, owner, axis, box});
            }
        }
    }
    return found;
}

/// Calls visit(grid index, local offset into `volume`) over `box`, x fastest; false when the
/// box does not lie in the rank's uploaded block (then nothing is visited).
template <typename Visit>
bool visit_box(const Box& box, const Decomposition::Part& part, const DeviceVolume& volume,
               Visit visit) {
    for (int axis = 0; axis < 3; ++axis) {
        if (box.lower[axis] < part.interior_lower[axis] ||
            box.upper[axis] - part.interior_lower[axis] > volume.dims[axis]) {
            return false;
        }
    }
    if (volume.host_values.size() !=
        static_cast<std::size_t>(volume.dims[0] * volume.dims[1] * volume.dims[2])) {
        return false;
    }
    for (std::int64_t k = box.lower[2]; k < box.upper[2]; ++k) {
        for (std::int64_t j = box.lower[1]; j < box.upper[1]; ++j) {
            for (std::int64_t i = box.lower[0]; i < box.upper[0]; ++i) {
                const std::int64_t x = i - part.interior_lower[0];
                const std::int64_t y = j - part.interior_lower[1];
                const std::int64_t z = k - part.interior_lower[2];
                visit(Index3{i, j, k},
                      static_cast<std::size_t>(x + volume.dims[0] * (y + volume.dims[1] * z)));
            }
        }
    }
    return true;
}

/// The holder's side: its layer against the owner's values, in box order.
HaloMismatch compare_overlap(const Overlap& overlap, const Decomposition::Part& part,
                             const DeviceVolume& volume, const std::vector<float>& owned) {
    HaloMismatch result{overlap.holder, overlap.owner, overlap.axis};
    std::size_t next = 0;
    visit_box(overlap.box, part, volume, [&](const Index3& at, std::size_t offset) {
        if (next >= owned.size()) return;
        const float held = volume.host_values[offset];
        const float own = owned[next++];
        ++result.compared;
        if (held == own || (std::isnan(held) && std::isnan(own))) return;
        ++result.differing;
        const double difference = std::isnan(held) || std::isnan(own)
                                      ? std::numeric_limits<double>::infinity()
                                      : std::abs(static_cast<double>(held) - own);
        if (result.differing > 1 && difference <= result.largest) return;
        result.largest = difference;
        result.at = at;
        result.held = held;
        result.owned = own;
    });
    return result;
}

std::vector<double> to_values(const HaloMismatch& m) {
    return {static_cast<double>(m.holder),
            static_cast<double>(m.owner),
            static_cast<double>(m.axis),
            m.largest,
            static_cast<double>(m.at[0]),
            static_cast<double>(m.at[1]),
            static_cast<double>(m.at[2]),
            m.held,
            m.owned,
            static_cast<double>(m.differing),
            static_cast<double>(m.compared)};
}
constexpr std::size_t kMismatchValues = 11;

HaloMismatch from_values(const double* v) {
    HaloMismatch m;
    m.holder = static_cast<int>(v[0]);
    m.owner = static_cast<int>(v[1]);
    m.axis = static_cast<int>(v[2]);
    m.largest = v[3];
    m.at = {static_cast<std::int64_t>(v[4]), static_cast<std::int64_t>(v[5]),
            static_cast<std::int64_t>(v[6])};
    m.held = v[7];
    m.owned = v[8];
    m.differing = static_cast<std::int64_t>(v[9]);
    m.compared = static_cast<std::int64_t>(v[10]);
    return m;
}

}  // namespace

std::vector<HaloMismatch> compare_halos(Communicator& ranks, const Decomposition& grid,
                                        const DeviceVolume* mine) {
    const int me = ranks.rank();
    const std::vector<Overlap> all = overlaps(grid);
    // The owner's side: its interior values under each holder's layer, per holder in order.
    std::vector<std::vector<double>> to_holder(static_cast<std::size_t>(ranks.size()));
    for (const Overlap& overlap : all) {
        if (overlap.owner != me || !mine) continue;
        std::vector<double>& out = to_holder[static_cast<std::size_t>(overlap.holder)];
        visit_box(overlap.box, grid.parts[me], *mine, [&](const Index3&, std::size_t offset) {
            out.push_back(mine->host_values[offset]);
        });
    }
    std::vector<Bytes> sent;
    for (const std::vector<double>& values : to_holder) sent.push_back(doubles_bytes(values));
    const std::vector<Bytes> received = ranks.all_to_all(sent);
    // The holder's side, owner by owner in the order they were sent.
    std::vector<double> found;
    std::vector<std::size_t> read(received.size(), 0);
    std::vector<std::vector<double>> from_owner;
    for (const Bytes& bytes : received) from_owner.push_back(bytes_doubles(bytes));
    for (const Overlap& overlap : all) {
        if (overlap.holder != me || !mine) continue;
        std::int64_t count = 1;
        for (int axis = 0; axis < 3; ++axis) {
            count *= overlap.box.upper[axis] - overlap.box.lower[axis];
        }
        const std::vector<double>& values = from_owner[static_cast<std::size_t>(overlap.owner)];
        std::size_t& first = read[static_cast<std::size_t>(overlap.owner)];
        if (first + static_cast<std::size_t>(count) > values.size()) continue;  // owner had none
        const std::vector<float> owned(values.begin() + static_cast<std::ptrdiff_t>(first),
                                       values.begin() + static_cast<std::ptrdiff_t>(first + count));
        first += static_cast<std::size_t>(count);
        const HaloMismatch result = compare_overlap(overlap, grid.parts[me], *mine, owned);
        if (result.differing == 0) continue;
        const std::vector<double> values_of = to_values(result);
        found.insert(found.end(), values_of.begin(), values_of.end());
    }
    std::vector<HaloMismatch> mismatches;
    for (const Bytes& bytes : ranks.all_gather(doubles_bytes(found))) {
        const std::vector<double> values = bytes_doubles(bytes);
        for (std::size_t at = 0; at + kMismatchValues <= values.size(); at += kMismatchValues) {
            mismatches.push_back(from_values(values.data() + at));
        }
    }
    return mismatches;
}

std::string describe(const HaloMismatch& m, const Decomposition& grid, std::int64_t step,
                     double span) {
    const char* units = grid.centering == Centering::cell ? "cells" : "samples";
    const char axis = "xyz"[m.axis];
    std::ostringstream out;
    out.precision(4);
    out << "step " << step << ": field \"" << grid.field << "\": the ghost layer rank " << m.holder
        << " hands over on its high " << axis << " side differs from rank " << m.owner
        << "'s interior there in " << m.differing << " of " << m.compared << " " << units
        << " (largest difference " << m.largest;
    if (span > 0.0 && std::isfinite(m.largest)) {
        out << ", " << 100.0 * m.largest / span << " % of the field's range";
    }
    out << ", at " << units << " x " << m.at[0] << ", y " << m.at[1] << ", z " << m.at[2] << ": "
        << m.held << " against " << m.owned << "): rank " << m.holder
        << " draws the space between the two from that layer, so the picture is not the "
           "field's; update the halos after the step's last write, before execute (\"halo_check\": "
           "\"off\" silences this check)";
    return out.str();
}

}  // namespace insitu
