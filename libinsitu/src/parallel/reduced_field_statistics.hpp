#pragma once
// FieldStatistics of a distributed field: each rank uploads its block (with the ghost layer the
// march needs) and the range, histograms and counts are those of the samples each rank owns,
// reduced over the ranks. Every member is a collective every rank calls in the same order; a
// rank that fails locally still takes part and the next agreement raises it on every rank.
#include <optional>
#include <string>
#include <vector>

#include "insitu/parallel/communicator.hpp"
#include "insitu/parallel/decomposition.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "parallel/agreement.hpp"
#include "step/field_plan.hpp"

namespace insitu {

class ReducedFieldStatistics final : public FieldStatistics {
public:
    /// Agrees on every block's extent (decomposing the grid the same way on every rank), uploads
    /// this rank's block of field `name` (`blocks`: none, one, or tiles joined into
    /// `joined_storage`) and reduces the range. Time spent in collectives adds to
    /// `collective_seconds`.
    ReducedFieldStatistics(Communicator& ranks, ProxyRenderer& renderer, const std::string& name,
                           const std::vector<const Field*>& blocks,
                           std::vector<float>& joined_storage, double& collective_seconds);

    const Bounds& bounds() const override { return grid_->bounds; }
    bool has_block() const override { return block_.has_value(); }
    BlockPlacement placement() const override;
    const ValueRange& range() const override { return range_; }
    ValueHistogram histogram() override;
    IntervalSet intervals(int count, IntervalMode mode, const TransferFunction& tf) override;
    /// The halo check (parallel/halo_check.hpp) of the uploaded blocks, collective: one warning
    /// line per ghost layer that differs from its owner's interior, on every rank.
    std::vector<std::string> check_halos(std::int64_t step);

    /// The samples every rank owns, at `root` (by rank; empty lists elsewhere), agreed first:
    /// what assemble_whole() makes the whole grid of. Collective.
    std::vector<Bytes> gather_owned(int root);
    /// The whole grid as one process holds it, from gather_owned()'s lists (`storage` holds the
    /// values): float samples from the first one on, the grid's spacing. Local; throws Error
    /// where a rank's list does not fill its part.
    Field assemble_whole(const std::vector<Bytes>& owned, std::vector<float>& storage) const;

private:
    /// Sums `counts` over the ranks and agrees (raising any rank's failure since the last).
    void sum_over_ranks(std::vector<double>& counts);
    void reduce_range();
    double min() const { return range_.empty() ? 0.0 : range_.min; }
    double max() const { return range_.empty() ? 0.0 : range_.max; }

    Communicator& ranks_;
    ProxyRenderer& renderer_;
    double& collective_seconds_;
    LocalFailure failure_;
    std::optional<Field> block_;
    std::optional<Decomposition> grid_;
    ValueRange range_;
};

}  // namespace insitu
