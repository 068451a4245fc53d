#include "parallel/reduced_field_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/elapsed.hpp"
#include "parallel/halo_check.hpp"

namespace insitu {

ReducedFieldStatistics::ReducedFieldStatistics(Communicator& ranks, ProxyRenderer& renderer,
                                               const std::string& name,
                                               const std::vector<const Field*>& blocks,
                                               std::vector<float>& joined_storage,
                                               double& collective_seconds)
    : ranks_(ranks), renderer_(renderer), collective_seconds_(collective_seconds) {
    failure_.guard([&] {
        if (blocks.size() == 1) block_ = *blocks.front();
        if (blocks.size() > 1) block_ = join_blocks(blocks, joined_storage);
    });
    // Every rank learns every block's extent, and decomposes the grid the same way.
    const BlockExtent mine = block_ ? BlockExtent::of(*block_) : BlockExtent{};
    const auto start = SteadyClock::now();
    const std::vector<Bytes> extents = agree(ranks_, failure_, doubles_bytes(mine.to_values()));
    collective_seconds_ += seconds_since(start);
    std::vector<BlockExtent> all;
    for (const Bytes& bytes : extents) {
        const std::vector<double> values = bytes_doubles(bytes);
        if (values.size() != BlockExtent::kValues) fail<Error>("block extent of a rank cut short");
        all.push_back(BlockExtent::from_values(values.data()));
    }
    grid_ = decompose(name, all);
    reduce_range();
}

void ReducedFieldStatistics::reduce_range() {
    // This rank's part: the upload, and what it owns of the range.
    const int me = ranks_.rank();
    ValueRange local;
    local.min = std::numeric_limits<double>::infinity();
    local.max = -local.min;
    failure_.guard([&] {
        if (!block_) return;
        renderer_.upload(grid_->marched_block(*block_, me));
        renderer_.set_region(grid_->region(me));
        const DeviceVolume& volume = renderer_.volume();
        const ValueRange counts = grid_->owned_counts(volume.host_values, volume.dims, me);
        local.finite_count = counts.finite_count;
        local.nonfinite_count = counts.nonfinite_count;
        // The marched ghost layer holds the neighbour's own values, so min and max over the
        // marched blocks are those of the grid.
        if (!volume.range.empty()) {
            local.min = volume.range.min;
            local.max = volume.range.max;
        }
    });
    // The agreement carries every rank's range: one collective, not one per reduction (each
    // costs the ranks a wake-up; bench/RESULTS.md, "Compositing cost under MPI"). Min, max and
    // sums of integer counts do not depend on the order they are taken in.
    const auto start = SteadyClock::now();
    const std::vector<Bytes> ranges =
        agree(ranks_, failure_,
              doubles_bytes({local.min, local.max, static_cast<double>(local.finite_count),
                             static_cast<double>(local.nonfinite_count)}));
    collective_seconds_ += seconds_since(start);
    double low = std::numeric_limits<double>::infinity();
    double high = -low;
    double counts[2] = {0.0, 0.0};
    for (const Bytes& bytes : ranges) {
        const std::vector<double> values = bytes_doubles(bytes);
        if (values.size() != 4) fail<Error>("value range of a rank cut short");
        low = std::min(low, values[0]);
        high = std::max(high, values[1]);
        counts[0] += values[2];
        counts[1] += values[3];
    }
    range_.finite_count = static_cast<std::int64_t>(counts[0]);
    range_.nonfinite_count = static_cast<std::int64_t>(counts[1]);
    if (!range_.empty()) {
        range_.min = low;
        range_.max = high;
    }
}

void ReducedFieldStatistics::sum_over_ranks(std::vector<double>& counts) {
    const auto start = SteadyClock::now();
    agree_on_sum(ranks_, failure_, counts);
    collective_seconds_ += seconds_since(start);
}

ValueHistogram ReducedFieldStatistics::histogram() {
    // The grid's histogram: the sum of the ranks' counts of the samples each owns, over the
    // agreed range (a rank without a block adds zeros, as every rank reduces).
    ValueHistogram histogram = ValueHistogram::of({}, min(), max());
    failure_.guard([&] {
        if (!block_) return;
        const DeviceVolume& volume = renderer_.volume();
        histogram = ValueHistogram::of(
            grid_->owned_values(volume.host_values, volume.dims, ranks_.rank()), min(), max());
    });
    sum_over_ranks(histogram.counts);
    return histogram;
}

IntervalSet ReducedFieldStatistics::intervals(int count, IntervalMode mode,
                                              const TransferFunction& tf) {
    if (mode == IntervalMode::uniform) return IntervalSet::uniform(min(), max(), count);
    // The sum of the ranks' histograms of the samples each owns: the grid's histogram.
    const std::size_t bins = static_cast<std::size_t>(64 * count);
    std::vector<double> histogram(bins, 0.0);
    failure_.guard([&] {
        if (!block_) return;
        const DeviceVolume& volume = renderer_.volume();
        histogram = IntervalSet::equalization_histogram(
            grid_->owned_values(volume.host_values, volume.dims, ranks_.rank()), min(), max(),
            count);
    });
    if (histogram.size() != bins) histogram.assign(bins, 0.0);  // as every rank reduces
    sum_over_ranks(histogram);
    return mode == IntervalMode::opacity_adaptive
               ? IntervalSet::opacity_adaptive(histogram, min(), max(), count, tf)
               : IntervalSet::from_equalization_histogram(histogram, min(), max(), count);
}

BlockPlacement ReducedFieldStatistics::placement() const {
    BlockPlacement mine;
    mine.grid_dims = grid_->dims;
    mine.origin = grid_->first_sample;
    mine.spacing = grid_->spacing;
    mine.count = 0;
    for (std::size_t r = 0; r < grid_->parts.size(); ++r) {
        const Decomposition::Part& part = grid_->parts[r];
        if (!part.present) continue;
        if (static_cast<int>(r) == ranks_.rank()) {
            mine.index = mine.count;
            mine.offset = part.interior_lower;
            mine.dims = part.interior_dims;
        }
        ++mine.count;
    }
    return mine;
}

std::vector<Bytes> ReducedFieldStatistics::gather_owned(int root) {
    Bytes mine;
    failure_.guard([&] {
        if (!block_) return;
        const DeviceVolume& volume = renderer_.volume();
        const std::vector<float> owned =
            grid_->owned_values(volume.host_values, volume.dims, ranks_.rank());
        mine.resize(owned.size() * sizeof(float));
        if (!owned.empty()) std::memcpy(mine.data(), owned.data(), mine.size());
    });
    const auto start = SteadyClock::now();
    agree(ranks_, failure_);
    std::vector<Bytes> owned = ranks_.gather(mine, root);
    collective_seconds_ += seconds_since(start);
    return owned;
}

Field ReducedFieldStatistics::assemble_whole(const std::vector<Bytes>& owned,
                                             std::vector<float>& storage) const {
    const Index3& dims = grid_->dims;
    storage.assign(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]),
                   std::numeric_limits<float>::quiet_NaN());
    for (std::size_t r = 0; r < grid_->parts.size(); ++r) {
        const Decomposition::Part& part = grid_->parts[r];
        if (!part.present) continue;
        Index3 marched = part.interior_dims;
        for (int axis = 0; axis < 3; ++axis) marched[axis] += part.marched_ghosts[axis];
        const Index3 box = grid_->owned_dims(marched, static_cast<int>(r));
        const std::size_t row = static_cast<std::size_t>(box[0]);
        const std::size_t count = row * static_cast<std::size_t>(box[1] * box[2]);
        if (r >= owned.size() || owned[r].size() != count * sizeof(float)) {
            fail<Error>(grid_->field, ": rank ", r, " sent ",
                        r < owned.size() ? owned[r].size() / sizeof(float) : 0, " samples of the ",
                        count, " it owns");
        }
        for (std::int64_t k = 0; k < box[2]; ++k) {
            for (std::int64_t j = 0; j < box[1]; ++j) {
                const Index3& at = part.interior_lower;
                const std::size_t to =
                    static_cast<std::size_t>(((at[2] + k) * dims[1] + at[1] + j) * dims[0] + at[0]);
                const std::size_t from = static_cast<std::size_t>(k * box[1] + j) * row;
                std::memcpy(storage.data() + to, owned[r].data() + from * sizeof(float),
                            row * sizeof(float));
            }
        }
    }
    Field whole(grid_->field, storage.data(), ScalarType::float32, dims);
    // Node centring at the first sample: where the renderers sample a cell-centred grid too.
    whole.set_origin(grid_->first_sample).set_spacing(grid_->spacing);
    return whole;
}

std::vector<std::string> ReducedFieldStatistics::check_halos(std::int64_t step) {
    const auto start = SteadyClock::now();
    agree(ranks_, failure_);  // every rank uploaded its block, or all raise the failure
    const std::vector<HaloMismatch> mismatches =
        compare_halos(ranks_, *grid_, block_ ? &renderer_.volume() : nullptr);
    collective_seconds_ += seconds_since(start);
    std::vector<std::string> lines;
    for (const HaloMismatch& mismatch : mismatches) {
        lines.push_back(describe(mismatch, *grid_, step, max() - min()));
    }
    return lines;
}

}  // namespace insitu
