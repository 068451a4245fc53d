#include "step/step_passes.hpp"

#include "insitu/render/distortion_camera.hpp"

namespace insitu {

ProxyFrame LocalPasses::proxies(const OrbitView& orbit, const Bounds& bounds, double tilt_deg,
                                bool multi_perspective, const ProxyRequest& request) {
    if (multi_perspective) {
        return renderer_.render(DistortionCamera::orbit(orbit, bounds, tilt_deg), request);
    }
    return renderer_.render(Camera::orbit(orbit, bounds), request);
}

}  // namespace insitu
