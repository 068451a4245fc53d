#include "step/local_field_statistics.hpp"

namespace insitu {

LocalFieldStatistics::LocalFieldStatistics(ProxyRenderer& renderer, const Field& field)
    : renderer_(renderer) {
    renderer_.upload(field);
}

ValueHistogram LocalFieldStatistics::histogram() {
    const DeviceVolume& volume = renderer_.volume();
    return volume.range.empty()
               ? ValueHistogram::of({}, 0.0, 0.0)
               : ValueHistogram::of(volume.host_values, volume.range.min, volume.range.max);
}

IntervalSet LocalFieldStatistics::intervals(int count, IntervalMode mode,
                                            const TransferFunction& tf) {
    return renderer_.choose_intervals(count, mode, &tf);
}

BlockPlacement LocalFieldStatistics::placement() const {
    const DeviceVolume& volume = renderer_.volume();
    BlockPlacement whole;
    whole.grid_dims = volume.dims;
    whole.origin = volume.origin;
    whole.spacing = volume.spacing;
    whole.dims = volume.dims;
    return whole;
}

}  // namespace insitu
