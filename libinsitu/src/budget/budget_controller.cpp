#include "insitu/budget/budget_controller.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace insitu {

namespace {

/// ", 8 uniform intervals chosen, half chosen, full size chosen" and the views' measures.
void describe_views(std::ostream& out, const BudgetConfig& budget, const BudgetRecord& c,
                    int checks, double share) {
    out << c.intervals << " " << to_string(c.interval_mode) << " intervals"
        << (budget.chooses_intervals ? " chosen" : " (given)");
    if (c.precision) {
        out << ", " << to_string(*c.precision)
            << (budget.chooses_precision ? " chosen" : " (given)");
    }
    if (budget.chooses_size) {
        out << ", "
            << (c.size_divisor == 1 ? std::string("full size")
                                    : "1/" + std::to_string(c.size_divisor) + " of each side")
            << " chosen";
    }
    out << " at " << checks << " check(s); last measured " << c.psnr_db << " dB";
    if (budget.psnr_db) out << " (asked >= " << *budget.psnr_db << ")";
    // The PSNR is the least over the views: say which, and the stored view's own.
    if (c.views.size() > 1) {
        const auto worst =
            std::min_element(c.views.begin(), c.views.end(),
                             [](const auto& a, const auto& b) { return a.psnr_db < b.psnr_db; });
        out << " in its worst of " << c.views.size() << " views, azimuth " << std::showpos
            << worst->azimuth_offset_deg << std::noshowpos << " deg (stored view "
            << c.views.front().psnr_db << " dB)";
    }
    out << ", " << c.bytes / 1e6 << " MB";
    if (budget.bytes_per_step) out << " (<= " << share * *budget.bytes_per_step / 1e6 << ")";
    out << ", " << c.milliseconds << " ms per step";
    if (budget.ms_per_step) out << " (<= " << share * *budget.ms_per_step << ")";
    out << (c.met ? ", met" : ", NOT met: the closest candidate");
}

/// "; compressed field at 0.001 of the range kept, ...", "; light field 42 cameras at 128^2
/// chosen, ..." and "; colour model K = 8 chosen, ...".
void describe_other_choices(std::ostream& out, const BudgetRecord& c) {
    if (const auto& volume = c.volume) {
        out << "; compressed field at " << volume->relative_tolerance << " of the range "
            << (volume->met ? "kept, " : "NOT kept (none met the budget; the closest: ")
            << volume->psnr_db << " dB, " << volume->bytes / 1e6 << " MB, " << volume->milliseconds
            << " ms per step" << (volume->met ? "" : ")");
    }
    if (const auto& light_field = c.light_field) {
        out << "; light field " << light_field->cameras << " cameras at " << light_field->size
            << "^2 chosen, " << light_field->psnr_db << " dB, " << light_field->bytes / 1e6
            << " MB, " << light_field->milliseconds << " ms per step"
            << (light_field->met ? ", met" : ", NOT met: the closest candidate");
    }
    if (const auto& model = c.colour_model) {
        out << "; colour model K = " << model->clusters << " chosen, " << model->psnr_db
            << " dB, fitted in " << model->milliseconds << " ms"
            << (model->met ? ", met" : ", NOT met: the closest candidate");
    }
}

}  // namespace

BudgetController::BudgetController(BudgetConfig budget, std::size_t field_count)
    : budget_(std::move(budget)), share_(1.0 / static_cast<double>(field_count)) {}

BudgetRecord BudgetController::choice_for(const std::string& field, const ValueHistogram& histogram,
                                          const Check& check) {
    const auto [found, fresh] = fields_.try_emplace(field);
    FieldState& state = found->second;
    const bool moved = !fresh && histogram_distance(state.histogram, histogram) > kBudgetMovedShare;
    const bool due = fresh || moved || state.archived_since_check >= budget_.check_every;
    if (due) {
        state.choice = check();
        state.histogram = histogram;
        state.archived_since_check = 0;
        ++state.checks;
    }
    ++state.archived_since_check;
    BudgetRecord choice = state.choice;
    choice.checked = due;
    return choice;
}

std::string BudgetController::summary() const {
    std::ostringstream out;
    out << std::fixed << std::setprecision(1) << "budget: ";
    if (fields_.empty()) out << "no step checked";
    const char* separator = "";
    for (const auto& [field, state] : fields_) {
        out << separator << "field \"" << field << "\" ";
        describe_views(out, budget_, state.choice, state.checks, share_);
        describe_other_choices(out, state.choice);
        out << "; the check took " << state.choice.check_milliseconds << " ms";
        separator = "; ";
    }
    return out.str();
}

}  // namespace insitu
