#pragma once
// The step recipe: the one place that turns the configuration and a field's plan (with the
// budget's choice) into the passes a step runs for that field. The step captures with it; the
// error budget measures its candidates with the same requests, differing only where it says so
// (measured_single_pass).
#include <optional>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "step/field_plan.hpp"

namespace insitu {

/// The passes of each of a field's views.
struct ViewPasses {
    /// The single-perspective pass (tilt 0): depth layers, attenuation, ..., training renderings.
    ProxyRequest single;
    bool wants_single = false;
    /// Attenuation under each training function, from the same intervals, step and camera as
    /// its training rendering: the pairs seed 000 §6.2 learns from (where fits_colour_model).
    ProxyRequest training_attenuation;
    /// The colour model is fitted (InstrumentConfig: training functions that apply to the field,
    /// the model enabled, and the attenuation it maps stored), with these settings.
    bool fits_colour_model = false;
    ColourModelSettings colour_model;
    /// The training renderings are stored, not only fitted on ("keep_training_images").
    bool keeps_training_images = false;
    /// The volume distortion camera's pass.
    ProxyRequest multi;
    bool wants_multi = false;
    /// The preview, and with stores_rendering the stored view's "rendering".
    RenderSettings preview;
    bool stores_rendering = false;
};

/// Everything a step computes of one field.
struct FieldRecipe {
    ViewPasses view_passes;
    /// Each view as stored: at the budget's size where it chooses size.
    std::vector<ViewConfig> views;
    /// The views' storage precision where a budget chose it; none = the archive's.
    std::optional<StoragePrecision> precision;
    /// The light field's capture, where the configuration has one (seed 001).
    std::optional<LightFieldRequest> light_field;
};

/// The settings of a step's preview (and stored rendering): the ground truth every view of the
/// step is measured against; the Explorer renders the compressed field with them too.
RenderSettings preview_settings(const InstrumentConfig& config);

/// The recipe of `plan`'s field at this step (plan.budget, where set, is applied).
FieldRecipe field_recipe(const InstrumentConfig& config, const FieldPlan& plan);

/// The single-perspective pass with `intervals` as the error budget measures a candidate: the
/// step's pass, except that attenuation and its mean depth are always made (the held-out edit
/// goes through them, stored or not) and no training renderings (the colour model's chooser
/// measures those).
ProxyRequest measured_single_pass(const InstrumentConfig& config, const FieldPlan& plan,
                                  const IntervalSet& intervals);

}  // namespace insitu
