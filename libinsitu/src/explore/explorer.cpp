#include "insitu/explore/explorer.hpp"

#include <chrono>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "explore/frame_maker.hpp"
#include "explore/frame_plan.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "representation/representation.hpp"

namespace insitu {

using detail::frame_location;
using detail::FrameMaker;
using detail::FramePlan;
using detail::FrameSource;
using detail::has_attenuation;
using detail::may_make_from_volume;
using detail::plan_frame;

std::string to_string(ColourSource source) {
    switch (source) {
        case ColourSource::automatic:
            return "auto";
        case ColourSource::model:
            return "model";
        case ColourSource::recompose:
            return "recompose";
        case ColourSource::captured:
            return "captured";
        case ColourSource::stored:
            return "stored";
    }
    return "unknown";
}

std::string to_string(ProxySource source) {
    switch (source) {
        case ProxySource::automatic:
            return "auto";
        case ProxySource::single:
            return "single";
        case ProxySource::multi:
            return "multi";
        case ProxySource::lightfield:
            return "lightfield";
        case ProxySource::volume:
            return "volume";
    }
    return "unknown";
}

ProxySource parse_proxy_source(const std::string& text) {
    if (text == "auto") return ProxySource::automatic;
    if (text == "single") return ProxySource::single;
    if (text == "multi") return ProxySource::multi;
    if (text == "lightfield") return ProxySource::lightfield;
    if (text == "volume") return ProxySource::volume;
    fail<InvalidArgument>("source = \"", text,
                          "\" (expected auto, single, multi, lightfield or volume)");
}

ColourSource parse_colour_source(const std::string& text) {
    if (text == "auto") return ColourSource::automatic;
    if (text == "model") return ColourSource::model;
    if (text == "recompose") return ColourSource::recompose;
    fail<InvalidArgument>("colour = \"", text, "\" (expected auto, model or recompose)");
}

Explorer::Explorer(const std::string& archive_path, std::shared_ptr<ComputeDevice> device,
                   ArchiveOmissions omitted)
    : path_(archive_path), device_(std::move(device)), steps_(archive_path, omitted) {
    for (const std::unique_ptr<Representation>& representation : representations()) {
        frame_makers_.push_back(representation->frame_maker(device_));
    }
}

Explorer::~Explorer() = default;

void Explorer::refresh() {
    std::lock_guard<std::mutex> lock(mutex_);
    steps_.refresh();
}

namespace {

/// The maker of the frames of `source` (every source plan_frame chooses has one).
FrameMaker& maker_of(const std::vector<std::unique_ptr<FrameMaker>>& makers, FrameSource source) {
    for (const std::unique_ptr<FrameMaker>& maker : makers) {
        if (maker->makes(source)) return *maker;
    }
    throw std::logic_error("no registered representation makes this frame source");
}

}  // namespace

ExploreFrame Explorer::render(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    const FramePlan plan = plan_frame(request, steps_, path_);
    // Only an edit's trust reads it (FrameBasis::attenuation_resolution).
    const double attenuation_resolution =
        plan.edits ? steps_.stored_attenuation_resolution() : kHalfAttenuationResolution;
    ExploreFrame frame =
        maker_of(frame_makers_, plan.source).render(plan, request, steps_, attenuation_resolution);
    frame.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return frame;
}

FrameRecipe Explorer::recipe(const ExploreRequest& request) {
    std::lock_guard<std::mutex> lock(mutex_);
    // A client draws the compressed field without the view's proxies: planned first where it
    // may make the frame.
    if (may_make_from_volume(request, steps_.archive())) {
        const FramePlan plan = plan_frame(request, steps_, path_);
        if (plan.source == FrameSource::volume) {
            return maker_of(frame_makers_, plan.source).recipe(plan, request, steps_);
        }
    }
    // Every other frame it draws over the view's single-perspective attenuation proxies (a light
    // field's too: they fill in where it knows nothing of a ray), as render() decides it.
    FrameRecipe recipe;
    const CachedStep& cached = steps_.load(request.step, request.view);
    if (!cached.single || !has_attenuation(*cached.single)) {
        recipe.why_not =
            frame_location(request, path_) + " has no single-perspective attenuation proxies";
        return recipe;
    }
    if (request.source == ProxySource::multi || request.source == ProxySource::lightfield) {
        recipe.why_not = "source = " + to_string(request.source);
        return recipe;
    }
    const FramePlan plan = plan_frame(request, steps_, path_);
    return maker_of(frame_makers_, plan.source).recipe(plan, request, steps_);
}

std::ostream& operator<<(std::ostream& out, const ExploreRequest& request) {
    out << "ExploreRequest{step " << request.step << ", view " << request.view;
    if (request.azimuth_deg) out << ", azimuth " << *request.azimuth_deg << " deg";
    if (request.elevation_deg) out << ", elevation " << *request.elevation_deg << " deg";
    if (request.transfer_function) out << ", edited " << *request.transfer_function;
    for (const auto& [interval, scale] : request.opacity_scales) {
        out << ", opacity x" << scale << " on interval " << interval;
    }
    out << ", colour " << to_string(request.colour) << ", source " << to_string(request.source);
    if (request.lighting) out << ", " << *request.lighting;
    if (request.ambient_occlusion) out << ", " << *request.ambient_occlusion;
    if (request.enhancement) out << ", " << *request.enhancement;
    return out << ", " << request.synthesis << "}";
}

}  // namespace insitu
