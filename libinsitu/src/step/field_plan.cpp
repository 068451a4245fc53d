#include "step/field_plan.hpp"

#include "insitu/core/layers.hpp"

namespace insitu {

FieldPlan plan_field(const InstrumentConfig& config, const std::string& name,
                     FieldStatistics& statistics) {
    FieldPlan plan;
    plan.name = name;
    plan.bounds = statistics.bounds();
    plan.has_block = statistics.has_block();
    plan.placement = statistics.placement();
    plan.summary.field = name;
    plan.summary.nonfinite_samples = statistics.range().nonfinite_count;
    plan.summary.histogram = statistics.histogram();
    const std::optional<TransferFunction>& configured = config.transfer_function_of(name);
    plan.transfer_function =
        configured ? *configured : default_transfer_function(plan.summary.histogram);
    const std::optional<std::vector<double>>& layers = config.layers_of(name);
    plan.isovalues =
        layers ? *layers
               : opacity_peaks(plan.transfer_function, statistics.range(), config.max_auto_layers);
    if (!config.budget || !config.budget->chooses_intervals) {
        plan.intervals = statistics.intervals(config.interval_count, config.interval_mode,
                                              plan.transfer_function);
    }
    return plan;
}

}  // namespace insitu
