#include "insitu/budget/colour_model_chooser.hpp"

#include <vector>

namespace insitu {

BudgetRecord::ColourModelChoice choose_colour_model(const BudgetShare& share,
                                                    const ColourModelMeasure& measure) {
    using Choice = BudgetRecord::ColourModelChoice;
    const auto affordable = [&](const Choice& c) { return share.affords_time(c.milliseconds); };
    const auto accurate = [&](const Choice& c) { return share.accurate(c.psnr_db); };
    std::vector<Choice> measured;
    for (const int clusters : kBudgetColourModelClusters) {
        const ColourModelMeasurement measurement = measure(clusters);
        measured.push_back(measurement.choice);
        // Fewest clusters first (the fit's time grows with K): the first that meets it is taken.
        if (share.accuracy_asked() && affordable(measurement.choice) &&
            accurate(measurement.choice)) {
            break;
        }
        // Fewer distinct attenuation vectors than K: a larger K fits the same model.
        if (measurement.fitted_clusters < clusters) break;
    }
    const Choice* chosen = choose_candidate(
        measured, share.accuracy_asked(), affordable, accurate,
        [](const Choice& a, const Choice& b) { return a.milliseconds < b.milliseconds; });
    Choice choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    return choice;
}

}  // namespace insitu
