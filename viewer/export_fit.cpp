#include "export_fit.hpp"

#include <numeric>

namespace insitu::viewer {
namespace {

/// `count` of `total` indices spread evenly from the first to the last (the first alone for 1).
std::vector<std::size_t> evenly_spaced(std::size_t total, std::size_t count) {
    std::vector<std::size_t> indices;
    for (std::size_t i = 0; i < count; ++i) {
        indices.push_back(count == 1 ? 0 : (i * (total - 1) * 2 + (count - 1)) / ((count - 1) * 2));
    }
    return indices;
}

}  // namespace

SiteFit fit_site(const std::vector<StepBytes>& steps, std::uintmax_t budget) {
    SiteFit fit;
    const auto all_bytes =
        std::accumulate(steps.begin(), steps.end(), std::uintmax_t{0},
                        [](std::uintmax_t sum, const StepBytes& s) { return sum + s.bytes; });
    const auto light_field_bytes = std::accumulate(
        steps.begin(), steps.end(), std::uintmax_t{0},
        [](std::uintmax_t sum, const StepBytes& s) { return sum + s.light_field_bytes; });
    fit.omitted.light_fields = all_bytes > budget && light_field_bytes > 0;
    const auto kept_bytes = [&](const StepBytes& s) {
        return s.bytes - (fit.omitted.light_fields ? s.light_field_bytes : 0);
    };
    const auto fits = [&](std::size_t count) {
        std::uintmax_t sum = 0;
        for (const std::size_t i : evenly_spaced(steps.size(), count)) sum += kept_bytes(steps[i]);
        return sum <= budget;
    };
    // The most steps that fit, counting down: with steps of unequal size fewer may not fit
    // where more do (which steps a count spreads over changes), so no bisection.
    std::size_t count = steps.size();
    while (count > 0 && !fits(count)) --count;
    for (const std::size_t i : evenly_spaced(steps.size(), count))
        fit.steps.push_back(steps[i].step);
    return fit;
}

}  // namespace insitu::viewer
