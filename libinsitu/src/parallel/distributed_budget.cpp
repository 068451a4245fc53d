#include "parallel/distributed_budget.hpp"

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "archive/manifest.hpp"
#include "budget/field_budget_check.hpp"
#include "core/elapsed.hpp"
#include "parallel/agreement.hpp"
#include "step/local_field_statistics.hpp"

namespace insitu {

BudgetRecord check_distributed_field_budget(Communicator& ranks, const InstrumentConfig& config,
                                            ReducedFieldStatistics& statistics,
                                            const FieldPlan& plan,
                                            std::unique_ptr<ProxyRenderer>& whole_field_renderer,
                                            double& collective_seconds) {
    constexpr int kRoot = 0;
    const std::vector<Bytes> owned = statistics.gather_owned(kRoot);
    LocalFailure failure;
    Bytes said;
    if (ranks.rank() == kRoot) {
        failure.guard([&] {
            std::vector<float> storage;
            const Field whole = statistics.assemble_whole(owned, storage);
            if (!whole_field_renderer) whole_field_renderer = std::make_unique<ProxyRenderer>();
            LocalFieldStatistics whole_statistics(*whole_field_renderer, whole);
            // The plan as one process makes it: the whole grid is this process's block.
            FieldPlan whole_plan = plan;
            whole_plan.has_block = true;
            whole_plan.placement = whole_statistics.placement();
            const BudgetRecord choice =
                check_field_budget(config, *whole_field_renderer, whole_statistics, whole_plan);
            // The manifest's form carries every member, doubles to the last bit.
            const std::string text = archive_format::budget_entry(choice).dump();
            said.assign(text.begin(), text.end());
        });
    }
    const auto start = SteadyClock::now();
    const std::vector<Bytes> told = agree(ranks, failure, said);
    collective_seconds += seconds_since(start);
    const Bytes& chosen = told.at(kRoot);
    return archive_format::budget_from_entry(
        nlohmann::json::parse(std::string(chosen.begin(), chosen.end())));
}

}  // namespace insitu
