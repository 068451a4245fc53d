#pragma once
// FieldStatistics of a field this process holds whole: the values uploaded to its renderer.
#include "insitu/render/proxy_renderer.hpp"
#include "step/field_plan.hpp"

namespace insitu {

class LocalFieldStatistics final : public FieldStatistics {
public:
    /// Uploads `field` to `renderer`: the one read of the simulation's memory. The upload packs
    /// the interior into the renderer's host staging vector and the device buffer; everything
    /// below reads those copies.
    LocalFieldStatistics(ProxyRenderer& renderer, const Field& field);

    const Bounds& bounds() const override { return renderer_.volume().bounds; }
    bool has_block() const override { return true; }
    BlockPlacement placement() const override;
    const ValueRange& range() const override { return renderer_.volume().range; }
    ValueHistogram histogram() override;
    IntervalSet intervals(int count, IntervalMode mode, const TransferFunction& tf) override;

private:
    ProxyRenderer& renderer_;
};

}  // namespace insitu
