#pragma once
// Attenuation maps stored smaller than the light field's maps
// (LightFieldSettings::attenuation_subsampling): the codec (light_field_exr.cpp) stores a_j and
// mean depth as EXR channels subsampled by the factor and reads them back at the full map size,
// so everything after the codec (reconstruction, the viewer's payload) sees full-size maps.
#include <OpenEXR/ImfInputPart.h>

#include <string>
#include <vector>

#include "archive/exr_frame.hpp"
#include "insitu/core/image.hpp"

namespace insitu::archive_format {

/// The a_j and mean depth of one camera, `factor` times smaller per side.
struct SubsampledAttenuation {
    Image attenuation;
    Image mean_depth;
};

/// a_j: the mean over each factor x factor block; mean depth: the a_j-weighted mean of the
/// block's finite depths, +inf where the block's a_j are all 0 (as the capture marks "no
/// material in this interval"). InvalidArgument unless `factor` divides the maps' size.
SubsampledAttenuation subsample_attenuation(const Image& attenuation, const Image& mean_depth,
                                            int factor);

/// Back to `size` per side: a_j bilinearly (texel centres aligned), then scaled per pixel so
/// that they sum to the full-size whole-ray opacity `alpha` (size^2 values), as captured a_j do
/// (proxy_renderer.hpp: a_j = sum of alpha_i T_i over the interval's samples): so silhouettes
/// and holes stay where the full-size colour maps have them, and only the split between
/// intervals is blurred. Mean depth: bilinearly with the weights w a_j over the taps where it is
/// defined, as the reconstruction interpolates it, so that empty texels do not pull it to +inf.
void upsample_attenuation(const SubsampledAttenuation& stored, const std::vector<float>& alpha,
                          Image& attenuation, Image& mean_depth);

/// The channels `names` of `part`, each subsampled by `factor` in x and y, as floats
/// (size / factor per side). The caller has checked the channels' sampling.
Image read_subsampled_channels(Imf::InputPart& part, const std::vector<std::string>& names,
                               int factor, const PartContext& where);

}  // namespace insitu::archive_format
