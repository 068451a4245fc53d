#pragma once
// StepPasses of a distributed run: each rank marches the samples of the field it owns (none
// without a block) and the partial results are composited at rank 0, which alone holds them.
// A rank whose pass fails still takes part in every composite and says so at finish().
#include "insitu/parallel/communicator.hpp"
#include "insitu/parallel/compositing_schedule.hpp"
#include "step/step_passes.hpp"

namespace insitu {

class CompositedPasses final : public StepPasses {
public:
    /// Time spent compositing adds to `composite_seconds`. finish() is called `finishes` times
    /// (once per representation); only the last agrees (see finish()). The images composite
    /// by `schedule` in groups of up to `radix` ranks (insitu/parallel/compositing_schedule.hpp).
    CompositedPasses(Communicator& ranks, ProxyRenderer& renderer, bool has_block,
                     double& composite_seconds, std::size_t finishes, CompositingSchedule schedule,
                     int radix)
        : ranks_(ranks),
          renderer_(renderer),
          has_block_(has_block),
          composite_seconds_(composite_seconds),
          finishes_left_(finishes),
          schedule_(schedule),
          radix_(radix) {}
    Image truth(const Camera& camera, const TransferFunction& tf,
                const RenderSettings& settings) override;
    ProxyFrame proxies(const OrbitView& orbit, const Bounds& bounds, double tilt_deg,
                       bool multi_perspective, const ProxyRequest& request) override;
    ProxyFrame light_field_pass(const Camera& camera, const ProxyRequest& request) override;
    bool holds_results() const override { return ranks_.rank() == 0; }
    bool holds_whole_field() const override { return false; }
    void finish() override;
    ProxyRenderer& renderer() override { return renderer_; }
    std::vector<Bytes> gather(const Bytes& payload) override;

private:
    Communicator& ranks_;
    ProxyRenderer& renderer_;
    bool has_block_;
    double& composite_seconds_;
    std::size_t finishes_left_;
    CompositingSchedule schedule_;
    int radix_;
};

}  // namespace insitu
