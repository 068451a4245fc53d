#pragma once
// The one spelling of an exploration request as text options, shared by `insitu-view render`
// (--key value) and the web viewer's /api/frame (?key=value), so that the same options give the
// same ExploreRequest and therefore the same pixels.
//
//   step=N  view=V  azimuth=DEG  elevation=DEG
//   tf=JSON-TEXT                     an edited transfer function (DESIGN.md TF JSON)
//   opacity-scale=J=S[,J=S...]       interval J's opacity scaled by S (>= 0)
//   segment-opacity=S=F[,S=F...]     light-field segment S's opacity scaled by F (>= 0)
//   colour=auto|model|recompose
//   source=auto|single|multi|lightfield   which stored proxies a new view is made from
//   light=AZ,EL[,DIFFUSE[,SPECULAR]][;AZ,EL...]   directional lights, orbit angles in degrees of
//                                    the direction toward the light, in world space; "camera" =
//                                    a headlight
//   ambient=A                        ambient term of the lighting (default 0.2)
//   ao=RADIUS[,STRENGTH]             proxy ambient occlusion (Eq. 5), radius in pixels; "on" = 8
//   enhance=LAMBDA,GAMMA             depth-aware enhancement (Eq. 11)
//   fill=PIXELS                      hole-filling radius of view synthesis
// Unknown keys and malformed values raise InvalidArgument naming the key and the value.
#include <map>
#include <string>

#include "insitu/explore/explorer.hpp"

namespace insitu::viewer {

using Options = std::map<std::string, std::string>;

/// Keys request_from_options understands.
const std::vector<std::string>& explore_option_keys();

/// Builds the request; InvalidArgument names the offending key and value.
ExploreRequest request_from_options(const Options& options);

}  // namespace insitu::viewer
