#pragma once
// The attenuation maps as the codec stores them at full size (LightFieldSettings's
// "attenuation_bits" and "mean_depth_subsampling"): each a_j as an integer share of the pixel's
// whole-ray opacity, and the mean depth subsampled. The reader gives back full-size maps, so
// everything after the codec (reconstruction, the viewer's payload) is unchanged.
//
// Why these two (bench/RESULTS.md, "Attenuation maps in a third of their bytes"): stored as half,
// a_j and mean depth take about 2 bytes per non-zero value each, zip compressing only the zeros;
// subsampling both lost the edits 0.7-2.4 dB, all of it the a_j's (the mean depth subsampled
// alone lost nothing), while a_j in 6-bit shares of the opacity lost nothing either.
#include <vector>

#include "insitu/core/image.hpp"

namespace insitu::archive_format {

/// What the codec stores of one camera's a_j and mean depth.
struct CodedAttenuation {
    Image attenuation;  ///< full size: the codes (bits > 0), or the a_j as given (bits 0)
    Image mean_depth;   ///< size / factor per side; +inf where the block's decoded a_j are 0
};

/// The whole ray's opacity per pixel, the segments' alphas composited front to back.
std::vector<float> whole_ray_alpha(const std::vector<Image>& segment_rgba);

/// a_j (L channels) and mean depth (L channels) of one camera, stored with a_j in 2^bits - 1
/// steps of `alpha` (bits 0: as given) and mean depth subsampled by `factor` (1, 2 or 4). The
/// mean depth is subsampled with the a_j the reader will decode as weights. `alpha` must be the
/// opacity as the reader will have it (the stored colour's).
CodedAttenuation encode_attenuation(const Image& attenuation, const Image& mean_depth,
                                    const std::vector<float>& alpha, int bits, int factor);

/// The inverse: full-size a_j (each pixel's summing to `alpha` where any code is > 0) and mean
/// depth (+inf where a_j is 0), every value a half. The number of steps cancels (a_j =
/// alpha q_j / sum q), so it needs only whether the a_j are codes.
void decode_attenuation(const CodedAttenuation& stored, const std::vector<float>& alpha, bool codes,
                        Image& attenuation, Image& mean_depth);

}  // namespace insitu::archive_format
