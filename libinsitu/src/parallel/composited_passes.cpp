#include "parallel/composited_passes.hpp"

#include <optional>

#include "core/elapsed.hpp"
#include "insitu/parallel/compositing.hpp"
#include "insitu/parallel/light_field_compositing.hpp"
#include "insitu/render/distortion_camera.hpp"

namespace insitu {

namespace {

/// Runs `composite` and adds its time to `seconds`.
template <typename Composite>
auto timed(double& seconds, Composite&& composite) {
    const auto start = SteadyClock::now();
    auto result = composite();
    seconds += seconds_since(start);
    return result;
}

}  // namespace

Image CompositedPasses::truth(const Camera& camera, const TransferFunction& tf,
                              const RenderSettings& settings) {
    std::optional<Rendering> partial;
    if (has_block_) {
        failure_.guard([&] { partial = renderer_.render_ground_truth(camera, tf, settings); });
    }
    // Every rank takes part in every composite, failed or not (see LocalFailure).
    Rendering composited;
    failure_.always([&] {
        composited = timed(composite_seconds_, [&] {
            return composite_rendering(ranks_, camera.width(), camera.height(),
                                       partial ? &*partial : nullptr, 0, schedule_, radix_);
        });
    });
    return composited.rgba;
}

ProxyFrame CompositedPasses::proxies(const OrbitView& orbit, const Bounds& bounds, double tilt_deg,
                                     bool multi_perspective, const ProxyRequest& request) {
    const Camera camera = Camera::orbit(orbit, bounds);
    const DistortionCamera distortion = DistortionCamera::orbit(orbit, bounds, tilt_deg);
    ProxyRequest march = request;
    march.training_transfer_functions.clear();
    std::optional<ProxyFrame> partial;
    if (has_block_) {
        failure_.guard([&] {
            partial = multi_perspective ? renderer_.render(distortion, march)
                                        : renderer_.render(camera, march);
        });
    }
    ProxyFrame frame;
    failure_.always([&] {
        frame = timed(composite_seconds_, [&] {
            const ProxyFrame shell = multi_perspective
                                         ? frame_shell(distortion.base(), tilt_deg, true, march)
                                         : frame_shell(camera, 0.0, false, march);
            return composite_proxies(ranks_, shell, partial ? &*partial : nullptr, 0, schedule_,
                                     radix_);
        });
    });
    for (const TransferFunction& tf : request.training_transfer_functions) {
        frame.training.push_back(truth(camera, tf, request.march));
    }
    return frame;
}

ProxyFrame CompositedPasses::light_field_pass(const Camera& camera, const ProxyRequest& request) {
    BlockPass march;
    if (has_block_ && !failure_.failed()) {
        march = [&](const ProxyRequest& pass) { return renderer_.render(camera, pass); };
    }
    // The marches in between are not compositing: only the exchanges' time counts as that.
    ProxyFrame frame = frame_shell(camera, 0.0, false, request);
    failure_.always([&] {
        frame = composite_light_field_pass(ranks_, camera, request, march, 0, &composite_seconds_);
    });
    return frame;
}

std::vector<Bytes> CompositedPasses::gather(const Bytes& payload) {
    std::vector<Bytes> payloads =
        timed(composite_seconds_, [&] { return agree(ranks_, failure_, payload); });
    if (!holds_results()) payloads.clear();
    return payloads;
}

void CompositedPasses::finish() {
    // Only the field's last finish agrees, before the step is queued: each collective costs
    // every rank a wake-up (bench/RESULTS.md, "Compositing cost under MPI"), and an earlier
    // one is not needed to keep the ranks in step. Every composite and gather is taken by
    // every rank whether or not it failed (failure_.always), so a representation after a
    // failure makes the same collectives on every rank, and the failure is raised here (or by
    // a gather's agreement before) on all of them.
    if (finishes_left_ > 1) {
        --finishes_left_;
        return;
    }
    const auto start = SteadyClock::now();
    agree(ranks_, failure_);
    composite_seconds_ += seconds_since(start);
}

}  // namespace insitu
