#include "insitu/budget/volume_chooser.hpp"

#include <iterator>
#include <vector>

namespace insitu {

BudgetRecord::VolumeChoice choose_volume(const BudgetShare& share, const VolumeMeasure& measure) {
    const std::vector<double> tolerances(std::begin(kBudgetVolumeTolerances),
                                         std::end(kBudgetVolumeTolerances));
    return measure_and_choose<BudgetRecord::VolumeChoice>(share, tolerances, measure);
}

}  // namespace insitu
