#include "representation/view_proxies/view_candidates.hpp"

#include <algorithm>
#include <limits>

#include "archive/exr_frame.hpp"
#include "core/elapsed.hpp"
#include "insitu/core/check.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "step/step_recipe.hpp"

namespace insitu {

ViewCandidates::ViewCandidates(const FieldBudgetCheck& check)
    : check_(check), view_(check.config.views_of(check.plan.name).front()) {
    const Camera& camera = check.views.front().camera;
    for (const int divisor : kBudgetSizeDivisors) {
        OrbitView orbit = view_.orbit;
        orbit.width /= divisor;
        orbit.height /= divisor;
        if (divisor == 1) {
            sizes_.push_back({1, camera, check.views.front().truth, check.stored_truth_ms});
        } else if (check.budget.chooses_size && orbit.width >= kBudgetMinViewSide &&
                   orbit.height >= kBudgetMinViewSide) {
            CandidateSize size{divisor, Camera::orbit(orbit, check.plan.bounds), {}, 0.0};
            const auto start = SteadyClock::now();
            size.rendering = check.renderer
                                 .render_ground_truth(size.camera, check.plan.transfer_function,
                                                      check.truth_settings)
                                 .rgba;
            size.preview_ms = milliseconds_since(start);
            sizes_.push_back(std::move(size));
        }
    }
    // Smallest first: within an interval count the cheaper sizes are measured first.
    std::reverse(sizes_.begin(), sizes_.end());
}

const Camera& ViewCandidates::camera_at(int size_divisor) const {
    const auto size = std::find_if(sizes_.begin(), sizes_.end(), [&](const CandidateSize& c) {
        return c.divisor == size_divisor;
    });
    INSITU_CHECK(size != sizes_.end());
    return size->camera;
}

BudgetRecord ViewCandidates::measure(int intervals, IntervalMode mode, std::size_t size,
                                     StoragePrecision precision) {
    const std::pair<int, IntervalMode> set{intervals, mode};
    if (!intervals_ || intervals_->first != set) {
        intervals_.emplace(
            set, check_.statistics.intervals(intervals, mode, check_.plan.transfer_function));
    }
    last_ = render(intervals_->second, intervals, mode, size);
    return measure(*last_, precision);
}

BudgetRecord ViewCandidates::measure_kept(StoragePrecision precision) {
    INSITU_CHECK(kept_.has_value());
    return measure(*kept_, precision);
}

ViewCandidates::CandidateProxies ViewCandidates::render(const IntervalSet& intervals, int count,
                                                        IntervalMode mode, std::size_t size) const {
    const CandidateSize& at = sizes_.at(size);
    const ProxyRequest request = measured_single_pass(check_.config, check_.plan, intervals);
    const auto start = SteadyClock::now();
    ProxyFrame frame = check_.renderer.render(at.camera, request);
    CandidateProxies proxies;
    proxies.count = count;
    proxies.mode = mode;
    proxies.size = size;
    proxies.pass_ms = milliseconds_since(start);
    proxies.scales = opacity_scales(check_.plan.transfer_function, check_.held_out, intervals);
    proxies.colours = interval_colours(check_.held_out, intervals);
    // Bytes as the writer stores the view (the rendering is the preview's size).
    if (check_.config.proxies.rendering) frame.rendering = at.rendering;
    proxies.view.field = check_.plan.name;
    proxies.view.view = view_;
    proxies.view.view.orbit.width = at.camera.width();
    proxies.view.view.orbit.height = at.camera.height();
    proxies.view.transfer_function = check_.plan.transfer_function;
    proxies.view.single = std::move(frame);
    return proxies;
}

BudgetRecord ViewCandidates::measure(const CandidateProxies& proxies,
                                     StoragePrecision precision) const {
    const CandidateSize& size = sizes_.at(proxies.size);
    const double view_count = static_cast<double>(check_.config.views_of(check_.plan.name).size());
    BudgetRecord candidate;
    candidate.field = check_.plan.name;
    candidate.intervals = proxies.count;
    candidate.interval_mode = proxies.mode;
    candidate.precision = precision;
    candidate.size_divisor = size.divisor;
    StepRecord record;
    record.field = check_.plan.name;
    const archive_format::EncodedView encoded = archive_format::encode_view(
        record, proxies.view, precision, check_.config.compression, "budget check");
    candidate.bytes = view_count * static_cast<double>(encoded.bytes.size());
    candidate.milliseconds = view_count * (proxies.pass_ms + size.preview_ms);
    const ProxyFrame stored =
        archive_format::decode_frame(std::vector<char>(encoded.bytes.begin(), encoded.bytes.end()),
                                     "budget check", encoded.parts, false);
    candidate.psnr_db = std::numeric_limits<double>::infinity();
    for (const BudgetView& target : check_.views) {
        const bool turned = &target != &check_.views.front();
        const double psnr_db = psnr_as_shown(
            target.truth, recolour(held_out_attenuation(stored, size.camera, turned,
                                                        target.azimuth_offset_deg, proxies.scales),
                                   proxies.colours));
        candidate.views.push_back({target.azimuth_offset_deg, psnr_db});
        candidate.psnr_db = std::min(candidate.psnr_db, psnr_db);
    }
    return candidate;
}

}  // namespace insitu
