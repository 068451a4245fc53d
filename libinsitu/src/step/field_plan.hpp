#pragma once
// A field's plan at one step: what its representations are computed from (the whole grid's
// bounds, the layers, the intervals, the transfer function, the values' summary) and the one
// planner that chooses them, for one process and for a distributed run alike. The statistics it
// plans from come from a FieldStatistics: this process's uploaded field, or the ranks' blocks
// reduced over the ranks.
#include <optional>
#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/field.hpp"

namespace insitu {

/// Where this process's block of a field lies in the whole grid: all of it for one process; a
/// rank's interior in a distributed run (what the rank keeps of the compressed field).
struct BlockPlacement {
    Index3 grid_dims{0, 0, 0};  ///< the whole grid's samples
    glm::dvec3 origin{0.0};     ///< world position of the whole grid's sample (0, 0, 0)
    glm::dvec3 spacing{1.0};    ///< world units between samples
    Index3 offset{0, 0, 0};     ///< of the block's first interior sample
    Index3 dims{0, 0, 0};       ///< the block's interior samples (none where it has no block)
    int index = 0;              ///< among the ranks with a block, by rank
    int count = 1;              ///< how many ranks have a block
};

/// The values of one field at one step, as the planner reads them: the field uploaded to this
/// process's renderer, or every rank's block of it (each call a collective every rank makes).
class FieldStatistics {
public:
    virtual ~FieldStatistics() = default;
    /// The whole grid's bounds.
    virtual const Bounds& bounds() const = 0;
    /// False on a rank of a distributed run that owns nothing of the field.
    virtual bool has_block() const = 0;
    /// Where the uploaded block's interior lies in the whole grid.
    virtual BlockPlacement placement() const = 0;
    /// The whole grid's value range and sample counts.
    virtual const ValueRange& range() const = 0;
    /// The whole grid's histogram over range() (ValueHistogram::of).
    virtual ValueHistogram histogram() = 0;
    /// `count` intervals over range() by `mode` (uniform, histogram-equalised over the grid's
    /// values, or opacity-adaptive under `tf`).
    virtual IntervalSet intervals(int count, IntervalMode mode, const TransferFunction& tf) = 0;
};

/// What the representations of one field are computed from at one step.
struct FieldPlan {
    std::string name;
    Bounds bounds;  ///< the whole grid's
    std::vector<double> isovalues;
    IntervalSet intervals = IntervalSet::uniform(0.0, 1.0, 1);
    bool has_block = true;  ///< false: a rank that owns nothing of the field
    BlockPlacement placement;
    /// The whole grid's values at this step (stored with the step, and what "auto" spans).
    FieldSummaryRecord summary;
    /// The configured function, or for "auto" default_transfer_function(summary.histogram).
    TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
    /// With a "budget": what it archives the field with at this step.
    std::optional<BudgetRecord> budget;
};

/// The plan of field `name` from its statistics: the function ("auto" spans the histogram's
/// percentiles), the layers (configured, or the function's opacity peaks) and, unless a budget
/// chooses them (it sets them with its choice), the configured intervals. Layers and intervals
/// come from this step's data: "model no more than a scene needs".
FieldPlan plan_field(const InstrumentConfig& config, const std::string& name,
                     FieldStatistics& statistics);

}  // namespace insitu
