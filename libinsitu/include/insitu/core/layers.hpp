#pragma once
// Layers: isovalues whose first crossing along each ray becomes a depth proxy (seed 000 §3.1).
// Given explicitly, or chosen as the peaks of the transfer function's opacity (seed 000 §7:
// features a user made opaque are the surfaces worth keeping).
#include <vector>

#include "insitu/core/transfer_function.hpp"
#include "insitu/field.hpp"

namespace insitu {

constexpr int kMaxLayers = 16;

/// Values where the opacity of `tf` (its first gradient row) has a local maximum, a plateau
/// counting once at its centre, restricted to [range.min, range.max] of the data. At most
/// `max_layers`, the most opaque first, returned in increasing value order. A plateau that runs
/// to an end of the function (where it clamps) counts at its inner edge. When no peak lies inside
/// the data's range, one layer is placed where the opacity first reaches half its largest value
/// over that range. Empty when the function is transparent over the data's range.
std::vector<double> opacity_peaks(const TransferFunction& tf, const ValueRange& range,
                                  int max_layers);

/// Throws InvalidArgument naming the value for non-finite isovalues or more than kMaxLayers.
void validate_isovalues(const std::vector<double>& isovalues);

}  // namespace insitu
