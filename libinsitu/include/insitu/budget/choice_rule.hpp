#pragma once
// The error budget's rule over the candidates it measured (insitu/config.hpp, BudgetConfig), the
// one rule every representation's chooser applies, and a field's share of a step's limits.
#include <algorithm>
#include <limits>
#include <vector>

#include "insitu/budget/budget_config.hpp"

namespace insitu {

/// One field's share of a step's limits (the fields share the step's bytes and time evenly), less
/// what the choices made before this one spent of it (a light field gets what the views left).
struct BudgetShare {
    const BudgetConfig& budget;
    double share = 1.0;        ///< 1 / the configuration's field count
    double spent_bytes = 0.0;  ///< bytes per step the earlier choices take
    double spent_ms = 0.0;     ///< milliseconds per step the earlier choices take

    bool affords_bytes(double bytes) const {
        return !budget.bytes_per_step || spent_bytes + bytes <= share * *budget.bytes_per_step;
    }
    bool affords_time(double milliseconds) const {
        return !budget.ms_per_step || spent_ms + milliseconds <= share * *budget.ms_per_step;
    }
    /// Whether a measured PSNR meets the accuracy the budget asks (any, where it asks none).
    bool accurate(double psnr_db) const { return !budget.psnr_db || psnr_db >= *budget.psnr_db; }
    bool accuracy_asked() const { return budget.psnr_db.has_value(); }
};

/// With an accuracy asked, the cheapest candidate that meets every limit; else (or where none
/// does) the cheapest affordable one within kBudgetPsnrTolerance of the most accurate affordable
/// one; else the cheapest. `Candidate` has `psnr_db`; `measured` is not empty.
template <typename Candidate, typename Affordable, typename Accurate, typename Cheaper>
const Candidate* choose_candidate(const std::vector<Candidate>& measured, bool accuracy_asked,
                                  const Affordable& affordable, const Accurate& accurate,
                                  const Cheaper& cheaper) {
    const Candidate* chosen = nullptr;
    for (const Candidate& c : measured) {
        if (accuracy_asked && affordable(c) && accurate(c) && (!chosen || cheaper(c, *chosen))) {
            chosen = &c;
        }
    }
    if (!chosen) {
        double best_db = -std::numeric_limits<double>::infinity();
        for (const Candidate& c : measured) {
            if (affordable(c)) best_db = std::max(best_db, c.psnr_db);
        }
        for (const Candidate& c : measured) {
            if (affordable(c) && c.psnr_db >= best_db - kBudgetPsnrTolerance &&
                (!chosen || cheaper(c, *chosen))) {
                chosen = &c;
            }
        }
    }
    if (!chosen) {
        for (const Candidate& c : measured) {
            if (!chosen || cheaper(c, *chosen)) chosen = &c;
        }
    }
    return chosen;
}

/// A representation's search: measures `parameters` in order, cheapest first, until one meets
/// the budget (the first that does is the cheapest), then chooses among those measured by bytes
/// (choose_candidate) and sets `met`. `Choice` has `bytes`, `milliseconds`, `psnr_db`, `met`.
template <typename Choice, typename Parameter, typename Measure>
Choice measure_and_choose(const BudgetShare& share, const std::vector<Parameter>& parameters,
                          const Measure& measure) {
    const auto affordable = [&](const Choice& c) {
        return share.affords_bytes(c.bytes) && share.affords_time(c.milliseconds);
    };
    const auto accurate = [&](const Choice& c) { return share.accurate(c.psnr_db); };
    std::vector<Choice> measured;
    for (const Parameter& parameter : parameters) {
        measured.push_back(measure(parameter));
        if (share.accuracy_asked() && affordable(measured.back()) && accurate(measured.back())) {
            break;
        }
    }
    const Choice* chosen =
        choose_candidate(measured, share.accuracy_asked(), affordable, accurate,
                         [](const Choice& a, const Choice& b) { return a.bytes < b.bytes; });
    Choice choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    return choice;
}

}  // namespace insitu
