#include "explore/frame_basis.hpp"

#include <algorithm>
#include <glm/vec4.hpp>
#include <limits>
#include <optional>
#include <utility>

#include "explore/frame_plan.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/enhancement.hpp"
#include "insitu/explore/relighting.hpp"

namespace insitu::detail {

namespace {

cl::NDRange pixel_range(std::size_t pixels) {
    return cl::NDRange((pixels + 63) / 64 * 64);
}

/// Per-pixel combination steps of kernels/explore/explorer.cl on one colour image kept on the
/// device.
class Compositor {
public:
    Compositor(ComputeDevice& device, const Image& colour) : device_(device) {
        colour_.upload(device, colour, "explored colour");
        pixels_ = colour.pixel_count();
    }

    void apply_lighting_factor(const Image& lit_white) {
        DeviceImage lit;
        lit.upload(device_, lit_white, "lighting factor");
        cl::Kernel kernel = device_.opencl().kernel("explorer", "apply_lighting_factor");
        device_.opencl().launch(kernel, pixel_range(pixels_), cl::NullRange, colour_.buffer(),
                                lit.buffer(), static_cast<cl_uint>(pixels_));
    }

    void apply_occlusion(const Image& occlusion) {
        DeviceImage factor;
        factor.upload(device_, occlusion, "ambient occlusion");
        cl::Kernel kernel = device_.opencl().kernel("explorer", "apply_occlusion");
        device_.opencl().launch(kernel, pixel_range(pixels_), cl::NullRange, colour_.buffer(),
                                factor.buffer(), static_cast<cl_uint>(pixels_));
    }

    Image result() { return colour_.download(device_, "explored colour"); }

private:
    ComputeDevice& device_;
    DeviceImage colour_;
    std::size_t pixels_ = 0;
};

/// The edit's trust (transfer_function_edit.hpp) folded into the frame's confidence, on top of
/// the view's own mask. `stored_attenuation` holds a before an opacity edit replaced it.
void fold_edit_trust(const FrameBasis& basis, const Image& stored_attenuation, const EditPlan& plan,
                     const TransferFunction& stored_tf, const TransferFunction& shown_tf,
                     ComputeDevice& device, ExploreFrame& frame) {
    EditTrustInputs trust;
    trust.attenuation = plan.opacity_edited ? &stored_attenuation : &basis.attenuation;
    trust.mean_depth = &basis.mean_depth;
    trust.optical_depth = basis.optical_depth;
    trust.interleaving = basis.interleaving;
    trust.entry_depth = basis.entry_depth;
    if (basis.stored_rendering && !stored_tf.is_2d()) {
        trust.stored_rendering = basis.stored_rendering;
        trust.stored_colours = interval_colours(stored_tf, *basis.intervals);
        trust.stored_colour_spread = interval_colour_spread(stored_tf, *basis.intervals);
    }
    trust.edited_attenuation = plan.opacity_edited ? &basis.attenuation : nullptr;
    trust.scales = plan.scales;
    trust.colours = plan.colours;
    trust.colour_spread = interval_colour_spread(shown_tf, *basis.intervals);
    trust.attenuation_resolution = basis.attenuation_resolution;
    Image error = edit_error(trust);
    if (plan.use_model) {
        add_model_departure(error, frame.colour, recolour(basis.attenuation, plan.colours, device));
    }
    const Image confidence = edit_confidence(error);
    for (std::size_t p = 0; p < confidence.pixels.size(); ++p) {
        frame.confidence.pixels[p] = std::min(frame.confidence.pixels[p], confidence.pixels[p]);
    }
}

/// Steps 4-5 from attenuation: opacity edits turn a into a' (estimate_attenuation), then the
/// colour is recomposed from a' or predicted by the colour model; an edit's trust follows.
void colour_from_attenuation(FrameBasis& basis, const ExploreRequest& request,
                             const TransferFunction& stored_tf, const TransferFunction& shown_tf,
                             const std::string& where, ComputeDevice& device, ExploreFrame& frame) {
    const bool edits = request.transfer_function.has_value() || !request.opacity_scales.empty();
    const EditPlan plan =
        plan_edit(request, stored_tf, shown_tf, *basis.intervals, basis.model, where);
    // The trust of an edit compares the edited attenuation with the stored one, kept here.
    Image stored_attenuation;
    if (plan.opacity_edited) {
        frame.opacity_scales = plan.scales;
        stored_attenuation = std::move(basis.attenuation);
        basis.attenuation = estimate_attenuation(stored_attenuation, basis.mean_depth,
                                                 basis.optical_depth, plan.scales, device);
    }
    frame.colour_source = plan.use_model ? ColourSource::model : ColourSource::recompose;
    frame.colour = plan.use_model ? basis.model->predict(basis.attenuation, device)
                                  : recolour(basis.attenuation, plan.colours, device);
    if (edits) fold_edit_trust(basis, stored_attenuation, plan, stored_tf, shown_tf, device, frame);
}

/// 6. Lighting and occlusion, as factors on whichever colour step 5 produced: per interval from
/// the mean depths where there is attenuation, else from the front surface's normals.
void light_and_occlude(const FrameBasis& basis, const ExploreRequest& request,
                       const std::optional<LightingSettings>& lighting, const std::string& where,
                       ComputeDevice& device, ExploreFrame& frame) {
    const Camera& target = frame.camera;
    const bool has_attenuation = basis.attenuation.channels > 0;
    Image front;
    if (request.ambient_occlusion || (lighting && !has_attenuation)) {
        front = basis.front_depth ? basis.front_depth() : Image();
        if (front.pixels.empty()) {
            fail<InvalidArgument>(request.ambient_occlusion ? "ambient occlusion" : "lighting",
                                  " needs depth (layers or a light field), and ", where,
                                  " has none");
        }
    }
    if (lighting && !has_attenuation) {
        const Image normals =
            normals_from_depth(smooth_depth(front, target, device), target, device);
        frame.colour = shade(frame.colour, normals, target, *lighting, device);
    }
    Compositor compositor(device, frame.colour);
    if (lighting && has_attenuation) {
        const int interval_count = basis.attenuation.channels;
        const std::vector<float> white(3 * static_cast<std::size_t>(interval_count), 1.0f);
        compositor.apply_lighting_factor(
            light_volume(basis.attenuation, basis.mean_depth, white, target, *lighting, device));
    }
    if (request.ambient_occlusion) {
        compositor.apply_occlusion(
            ambient_occlusion(front, target, *request.ambient_occlusion, device));
    }
    frame.colour = compositor.result();
}

}  // namespace

FrontSurface::FrontSurface(ComputeDevice& device, const std::vector<Image>& layers)
    : device_(device), layers_(layers) {
    const Image& first = layers.front();
    pixels_ = first.pixel_count();
    front_.upload(device,
                  Image(first.width, first.height, 1, std::numeric_limits<float>::infinity()),
                  "front depth");
    cl::Kernel front_kernel = device.opencl().kernel("explorer", "front_depth");
    for (const Image& depth : layers) {
        layer_.upload(device, depth, "depth layer");
        device.opencl().launch(front_kernel, pixel_range(pixels_), cl::NullRange, front_.buffer(),
                               layer_.buffer(), static_cast<cl_uint>(pixels_));
    }
}

Image FrontSurface::depth() const {
    return front_.download(device_, "front depth");
}

Image FrontSurface::paint(const std::vector<double>& isovalues, const TransferFunction& tf) {
    const Image& first = layers_.front();
    DeviceImage colour;
    colour.upload(device_, Image(first.width, first.height, 4, 0.0f), "surface colour");
    cl::Kernel paint = device_.opencl().kernel("explorer", "paint_surface");
    for (std::size_t l = 0; l < layers_.size(); ++l) {
        const glm::vec4 rgba = tf.evaluate(l < isovalues.size() ? isovalues[l] : tf.value_min());
        const cl_float4 rgb{{rgba.r, rgba.g, rgba.b, 1.0f}};
        layer_.upload(device_, layers_[l], "depth layer");
        device_.opencl().launch(paint, pixel_range(pixels_), cl::NullRange, colour.buffer(),
                                layer_.buffer(), front_.buffer(), rgb,
                                static_cast<cl_uint>(pixels_));
    }
    return colour.download(device_, "surface colour");
}

void finish_frame(FrameBasis basis, const ExploreRequest& request,
                  const TransferFunction& stored_tf, const TransferFunction& shown_tf,
                  const std::string& where, ComputeDevice& device, ExploreFrame& frame) {
    const Camera& target = frame.camera;
    frame.confidence = std::move(basis.confidence);
    // Headlights (lights with a zero direction) point from the surface toward the camera.
    std::optional<LightingSettings> lighting = request.lighting;
    if (lighting) {
        for (Light& light : lighting->lights) {
            if (light.direction_world == glm::dvec3(0.0)) light.direction_world = -target.forward();
        }
    }
    const bool has_attenuation = basis.attenuation.channels > 0;
    const bool edits = request.transfer_function.has_value() || !request.opacity_scales.empty();
    if (!has_attenuation && request.enhancement) {
        fail<InvalidArgument>("depth-aware enhancement needs attenuation proxies, and ", where,
                              " has none");
    }
    if (!has_attenuation && !request.opacity_scales.empty()) {
        fail<InvalidArgument>("opacity-scale needs attenuation proxies, and ", where, " has none");
    }

    if (has_attenuation && (edits || basis.colour.pixels.empty())) {
        colour_from_attenuation(basis, request, stored_tf, shown_tf, where, device, frame);
    } else {
        if (request.transfer_function && !has_attenuation && !basis.colour_follows_edits) {
            fail<InvalidArgument>("a transfer-function edit needs attenuation proxies, and ", where,
                                  " has none");
        }
        frame.colour = std::move(basis.colour);
        // Painted surfaces are the transfer function's colours; a light field's are captured.
        frame.colour_source =
            basis.colour_follows_edits ? ColourSource::recompose : ColourSource::captured;
    }

    if (lighting || request.ambient_occlusion) {
        light_and_occlude(basis, request, lighting, where, device, frame);
    }

    // 7. Depth-aware enhancement (Eq. 11).
    if (request.enhancement) {
        frame.colour =
            enhance_depth_aware(frame.colour, basis.attenuation, *request.enhancement, device);
    }
}

}  // namespace insitu::detail
