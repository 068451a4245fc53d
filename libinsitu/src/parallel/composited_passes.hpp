#pragma once
// StepPasses of a distributed run: each rank marches the samples of the field it owns (none
// without a block) and the partial results are composited at rank 0, which alone holds them.
// A rank whose pass fails still takes part in every composite and says so at finish().
#include "insitu/parallel/communicator.hpp"
#include "step/step_passes.hpp"

namespace insitu {

class CompositedPasses final : public StepPasses {
public:
    /// Time spent compositing adds to `composite_seconds`.
    CompositedPasses(Communicator& ranks, ProxyRenderer& renderer, bool has_block,
                     double& composite_seconds)
        : ranks_(ranks),
          renderer_(renderer),
          has_block_(has_block),
          composite_seconds_(composite_seconds) {}
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
};

}  // namespace insitu
