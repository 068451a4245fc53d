#pragma once
// The error budget's controller: per field, the choice in force, when to check it again, what a
// step records of it, and the line finalize() says of it. What a check measures is the step's
// (a callback): the controller runs without a device in tests.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "insitu/archive/step_record.hpp"
#include "insitu/budget/budget_config.hpp"
#include "insitu/core/histogram.hpp"

namespace insitu {

class BudgetController {
public:
    /// `field_count`: the configuration's fields, which share a step's bytes and time evenly.
    BudgetController(BudgetConfig budget, std::size_t field_count);

    using Check = std::function<BudgetRecord()>;
    /// The choice `field` is archived with at this step, `checked` set where `check` measured it
    /// now: at the field's first step, once more than kBudgetMovedShare of its values moved
    /// since the last check (histogram_distance), and "check_every" archived steps after it.
    BudgetRecord choice_for(const std::string& field, const ValueHistogram& histogram,
                            const Check& check);

    /// "budget: field "v" 8 uniform intervals chosen, half chosen, full size chosen at 3
    /// check(s); last measured 41.2 dB (asked >= 40) in its worst of 3 views, azimuth +20 deg
    /// (stored view 44.0 dB), ...; the check took 35.0 ms".
    std::string summary() const;

private:
    /// One field's choice, the check that made it, and the field's histogram then.
    struct FieldState {
        BudgetRecord choice;
        std::int64_t archived_since_check = 0;
        ValueHistogram histogram;
        int checks = 0;
    };

    BudgetConfig budget_;
    double share_ = 1.0;
    std::map<std::string, FieldState> fields_;
};

}  // namespace insitu
