#pragma once
// What steps 4-7 of explorer.hpp start from, in the target camera (FrameBasis), the front-most
// surface of depth layers that some bases draw or light from, and the steps themselves
// (finish_frame): opacity edits and their trust, colour, lighting and occlusion, enhancement.
#include <functional>
#include <string>
#include <vector>

#include "device/device_image.hpp"
#include "insitu/core/image.hpp"
#include "insitu/core/intervals.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/device/compute_device.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/explorer.hpp"
#include "insitu/explore/transfer_function_edit.hpp"

namespace insitu::detail {

/// What steps 4-7 start from, in the target camera: attenuation proxies (recoloured, edited,
/// lit per interval) or, without them, a colour of its own (light-field RGBA, painted surfaces)
/// lit from the normals of its front depth.
struct FrameBasis {
    Image attenuation, mean_depth;  ///< empty: no attenuation
    const Image* optical_depth = nullptr;
    /// The stored view's interleaving counts; null for synthesised views (not re-projected) and
    /// archives without them: the edit trust then leaves that term out.
    const Image* interleaving = nullptr;
    /// Likewise the stored view's entry depths, and its exact rendering (the recolouring
    /// term's measure at the run's own function).
    const Image* entry_depth = nullptr;
    const Image* stored_rendering = nullptr;
    /// How exactly the archive stores a_j (EditTrustInputs::attenuation_resolution).
    double attenuation_resolution = kHalfAttenuationResolution;
    const IntervalSet* intervals = nullptr;  ///< with attenuation
    const ColourModel* model = nullptr;      ///< the view's colour model, when stored
    Image colour;                            ///< the frame's own colour; empty: recompose
    /// The own colour already shows an edited transfer function (painted surfaces).
    bool colour_follows_edits = false;
    std::function<Image()> front_depth;  ///< front-most surface depth, on demand (AO, normals)
    Image confidence;
};

/// The front-most surface over the depth layers (+inf where none hits), kept on the device:
/// ambient occlusion needs only its depth; without attenuation proxies the layers are also
/// painted as opaque surfaces in the transfer function's colour at each layer's isovalue.
class FrontSurface {
public:
    FrontSurface(ComputeDevice& device, const std::vector<Image>& layers);
    Image depth() const;
    Image paint(const std::vector<double>& isovalues, const TransferFunction& tf);

private:
    ComputeDevice& device_;
    const std::vector<Image>& layers_;
    std::size_t pixels_ = 0;
    DeviceImage front_, layer_;
};

/// Steps 4-7 of explorer.hpp on `basis`, into `frame` (colour, confidence, opacity scales).
void finish_frame(FrameBasis basis, const ExploreRequest& request,
                  const TransferFunction& stored_tf, const TransferFunction& shown_tf,
                  const std::string& where, ComputeDevice& device, ExploreFrame& frame);

}  // namespace insitu::detail
