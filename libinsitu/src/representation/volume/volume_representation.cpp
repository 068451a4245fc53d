#include "representation/volume/volume_representation.hpp"

#include "insitu/core/check.hpp"

namespace insitu {

void VolumeRepresentation::capture(const InstrumentConfig& config, const FieldPlan& plan,
                                   const FieldRecipe&, StepPasses& passes,
                                   StepRecord& record) const {
    if (!config.volume) return;
    // Refused with a communicator at construction: rank 0 alone writes, and the field is not
    // gathered to it.
    INSITU_CHECK(passes.holds_whole_field());
    const DeviceVolume& uploaded = passes.renderer().volume();
    const VolumeSettings& settings = *config.volume;
    VolumeRecord volume;
    volume.field = plan.name;
    volume.dims = uploaded.dims;
    volume.origin = uploaded.origin;
    volume.spacing = uploaded.spacing;
    volume.mode = settings.mode;
    volume.min = plan.summary.histogram.min;
    volume.max = plan.summary.histogram.max;
    volume.tolerance = settings.tolerance_for(volume.max - volume.min);
    volume.rate = settings.rate;
    volume.threads = settings.threads;
    // The uploaded copy is already the interior as float, NaN where the field is non-finite.
    volume.blocks.push_back({{0, 0, 0}, uploaded.dims, uploaded.host_values});
    record.volumes.push_back(std::move(volume));
}

void VolumeRepresentation::choose(const FieldBudgetCheck&, BudgetRecord&) const {}

}  // namespace insitu
