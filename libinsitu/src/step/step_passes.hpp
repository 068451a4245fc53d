#pragma once
// Where a step's passes run: on this process's renderer, or (parallel/composited_passes.hpp)
// on every rank's block, composited at rank 0. The representations capture through this one
// interface and never ask which.
#include "insitu/core/camera.hpp"
#include "insitu/core/image.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "parallel/agreement.hpp"

namespace insitu {

class StepPasses {
public:
    virtual ~StepPasses() = default;
    /// The ground truth of `tf` in `camera` (RGBA).
    virtual Image truth(const Camera& camera, const TransferFunction& tf,
                        const RenderSettings& settings) = 0;
    /// A view's single-perspective pass (tilt 0) or its volume distortion camera's.
    virtual ProxyFrame proxies(const OrbitView& orbit, const Bounds& bounds, double tilt_deg,
                               bool multi_perspective, const ProxyRequest& request) = 0;
    /// A light-field camera's pass (segments, first hit, attenuation): this process's pass, or
    /// every rank's block composited (insitu/parallel/light_field_compositing.hpp).
    virtual ProxyFrame light_field_pass(const Camera& camera, const ProxyRequest& request) = 0;
    /// Whether this process holds the passes' results (the only process, or rank 0).
    virtual bool holds_results() const = 0;
    /// Whether renderer() holds the whole field (one process), not a rank's block of it.
    virtual bool holds_whole_field() const = 0;
    /// Ends the field's passes: raises, on every rank, a failure of any rank's guarded work.
    virtual void finish() = 0;
    /// The renderer with the field (or this rank's block of it) uploaded.
    virtual ProxyRenderer& renderer() = 0;
    /// Every rank's `payload` by rank where the results are held (this process's alone for one
    /// process), none elsewhere; in a distributed run a collective that raises, on every rank,
    /// any rank's failure since the last.
    virtual std::vector<Bytes> gather(const Bytes& payload) = 0;
    /// Runs local work on the results (where held); a failure is raised by finish(), so that a
    /// rank that fails still takes part in every collective before it.
    template <typename Work>
    void guard(Work&& work) {
        failure_.guard(work);
    }

protected:
    LocalFailure failure_;
};

/// The passes of a field this process holds whole.
class LocalPasses final : public StepPasses {
public:
    explicit LocalPasses(ProxyRenderer& renderer) : renderer_(renderer) {}
    Image truth(const Camera& camera, const TransferFunction& tf,
                const RenderSettings& settings) override {
        return renderer_.render_ground_truth(camera, tf, settings).rgba;
    }
    ProxyFrame proxies(const OrbitView& orbit, const Bounds& bounds, double tilt_deg,
                       bool multi_perspective, const ProxyRequest& request) override;
    ProxyFrame light_field_pass(const Camera& camera, const ProxyRequest& request) override {
        return renderer_.render(camera, request);
    }
    bool holds_results() const override { return true; }
    bool holds_whole_field() const override { return true; }
    void finish() override { failure_.raise(); }
    ProxyRenderer& renderer() override { return renderer_; }
    std::vector<Bytes> gather(const Bytes& payload) override {
        failure_.raise();
        return {payload};
    }

private:
    ProxyRenderer& renderer_;
};

}  // namespace insitu
