#pragma once
// The error budget in a distributed run (issue 43 item 2). A check measures every candidate
// against the ground truth of the whole field, and which candidate it measures next depends on
// what the last one measured, so the ranks cannot each measure their block: rank 0 gathers the
// samples every rank owns, runs the one-process check on the whole grid (the same code, the same
// values: the choice one process makes) and every rank gets its choice with the agreement that
// ends the check. Collectives: an agreement, the gather, the agreement carrying the choice; a
// rank that fails in between still takes part, and the last agreement raises it on every rank.
// The cost: rank 0 holds the whole field as float during a check (once at the first step, then
// every "check_every" archived steps or when the values move), and the times it measures are
// one process's on the whole field.
#include <memory>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/parallel/communicator.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "parallel/reduced_field_statistics.hpp"
#include "step/field_plan.hpp"

namespace insitu {

/// One budget check of `plan`'s field, on every rank; `whole_field_renderer` is rank 0's
/// renderer of the gathered field (made at its first check, kept for the next). The gather and
/// the closing agreement (the other ranks' wait for rank 0's check) add to
/// `collective_seconds`.
BudgetRecord check_distributed_field_budget(Communicator& ranks, const InstrumentConfig& config,
                                            ReducedFieldStatistics& statistics,
                                            const FieldPlan& plan,
                                            std::unique_ptr<ProxyRenderer>& whole_field_renderer,
                                            double& collective_seconds);

}  // namespace insitu
