// InstrumentConfig::validate: the ranges a configuration accepts, a check per group of keys. The
// first value out of range is the one reported, so the checks run in a fixed order.
#include <algorithm>
#include <array>
#include <cmath>

#include "config_json.hpp"
#include "config_views.hpp"
#include "insitu/config.hpp"
#include "insitu/core/layers.hpp"

namespace insitu {

namespace {

using namespace config_json;

// OpenEXR's lossless and lossy codecs that every OpenEXR 3 build has.
constexpr std::array<const char*, 7> kCompressions = {"none", "rle",   "zips", "zip",
                                                      "piz",  "pxr24", "b44"};

void check_field_names(const std::vector<std::string>& fields) {
    if (fields.empty()) out_of_range("fields", "[]", "name at least one field");
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].empty()) out_of_range(element_key("fields", i), "\"\"", "empty name");
    }
}

void check_fields_distinct(const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
        const auto first = std::find(fields.begin(), fields.begin() + i, fields[i]);
        if (first != fields.begin() + i) {
            out_of_range(element_key("fields", i), "\"" + fields[i] + "\"", "repeats ",
                         element_key("fields", static_cast<std::size_t>(first - fields.begin())),
                         "; give each field once");
        }
    }
}

// A field's own settings, named by the field's index in "fields".
void check_field_styles(const InstrumentConfig& config) {
    const std::vector<std::string>& fields = config.fields;
    for (const auto& entry : config.field_styles) {
        // Not a structured binding: C++17 lambdas (below) cannot capture those.
        const std::string& name = entry.first;
        const FieldStyle& style = entry.second;
        const auto at = std::find(fields.begin(), fields.end(), name);
        if (at == fields.end()) {
            out_of_range("fields", "\"" + name + "\"", "has settings but is not listed");
        }
        const std::string key =
            element_key("fields", static_cast<std::size_t>(at - fields.begin()));
        if (style.views) validate_views(*style.views, child_key(key, "views"));
        if (style.layers) {
            checked(child_key(key, "layers"), list_text(*style.layers),
                    [&] { validate_isovalues(*style.layers); });
        }
    }
}

// "units": each names a listed field and says something a caption can show on one line.
void check_units(const InstrumentConfig& config) {
    for (const auto& entry : config.units) {
        const std::string key = child_key("units", entry.first);
        if (std::find(config.fields.begin(), config.fields.end(), entry.first) ==
            config.fields.end()) {
            out_of_range(key, "\"" + entry.second + "\"", "names no field in \"fields\"");
        }
        const bool printable = std::all_of(entry.second.begin(), entry.second.end(),
                                           [](char c) { return c != '\n' && c != '\r'; });
        if (entry.second.empty() || entry.second.size() > 32 || !printable) {
            out_of_range(key, "\"" + entry.second + "\"", "expected 1 to 32 characters, one line");
        }
    }
}

// "layers", "max_layers", "intervals" and "step": what the rays sample and what they store.
void check_sampling(const InstrumentConfig& config) {
    if (config.layers) {
        checked("layers", list_text(*config.layers), [&] { validate_isovalues(*config.layers); });
    }
    if (config.max_auto_layers < 1 || config.max_auto_layers > kMaxLayers) {
        out_of_range("max_layers", text_of(config.max_auto_layers), "must be in [1, ", kMaxLayers,
                     "]");
    }
    if (config.interval_count < 1 || config.interval_count > kMaxIntervals) {
        out_of_range("intervals.count", text_of(config.interval_count), "must be in [1, ",
                     kMaxIntervals, "]");
    }
    const double step_voxels = config.step_voxels;
    if (!(step_voxels > 0.0) || !std::isfinite(step_voxels)) {
        out_of_range("step", text_of(step_voxels), "voxels, must be finite and > 0");
    }
    if (step_voxels < kMinStepVoxels) {
        out_of_range("step", text_of(step_voxels), "voxels, must be >= ", kMinStepVoxels,
                     ": finer steps resample the same cells and float positions stop advancing");
    }
}

void check_cadence(std::int64_t every, const std::vector<std::int64_t>& steps) {
    if (every < 1) out_of_range("every", text_of(every), "must be an integer >= 1");
    for (std::size_t i = 0; i < steps.size(); ++i) {
        // Archive files are named by step number, and a listed step can be executed only once.
        if (steps[i] < 0) {
            out_of_range(element_key("steps", i), text_of(steps[i]), "step numbers must be >= 0");
        }
        const auto first = std::find(steps.begin(), steps.begin() + i, steps[i]);
        if (first != steps.begin() + i) {
            out_of_range(element_key("steps", i), text_of(steps[i]), "repeats ",
                         element_key("steps", static_cast<std::size_t>(first - steps.begin())));
        }
    }
}

void check_writer(const std::string& compression, int writer_queue) {
    if (std::find(kCompressions.begin(), kCompressions.end(), compression) == kCompressions.end()) {
        out_of_range("compression", "\"" + compression + "\"",
                     "expected none, rle, zips, zip, piz, pxr24 or b44");
    }
    if (writer_queue < 1) out_of_range("writer.queue", text_of(writer_queue), "must be >= 1");
}

bool any_2d_transfer_function(const InstrumentConfig& config) {
    bool two_d = config.transfer_function && config.transfer_function->is_2d();
    for (const auto& entry : config.field_styles) {
        two_d =
            two_d || (entry.second.transfer_function && entry.second.transfer_function->is_2d());
    }
    return two_d;
}

// A step's cost would otherwise be bounded by nothing the simulation can see before its run
// stalls. The estimate needs every other value in range, so this check comes last.
void check_cost(const InstrumentConfig& config) {
    const double samples = config.estimated_samples_per_step();
    if (samples > kMaxSamplesPerStep) {
        double pixels = 0.0;
        const std::vector<PlannedView> planned = config.planned_views();
        for (const PlannedView& planned_view : planned) {
            pixels +=
                static_cast<double>(planned_view.view.orbit.width) * planned_view.view.orbit.height;
        }
        fail<InvalidArgument>(
            "configuration: about ", samples, " samples per step, above the ceiling of ",
            kMaxSamplesPerStep, " (", kWorstDiagonalVoxels,
            "-voxel rays at \"step\" = ", config.step_voxels, " over \"views\": ", planned.size(),
            " views of ", config.fields.size(), " field(s), ", pixels, " pixels in all, ",
            config.passes_per_view(),
            " passes each from \"proxies\" and \"training_transfer_functions\"); raise \"step\" "
            "or reduce the others");
    }
}

}  // namespace

void InstrumentConfig::validate() const {
    check_field_names(fields);
    validate_views(views, "views");
    check_fields_distinct(fields);
    check_field_styles(*this);
    check_units(*this);
    check_sampling(*this);
    check_cadence(every, steps);
    if (archive.empty()) out_of_range("archive", "\"\"", "name the archive directory");
    if (light_field) light_field->validate();
    if (volume) volume->validate();
    check_writer(compression, writer_queue);
    if (budget) budget->validate(any_2d_transfer_function(*this));
    if (colour_model.clusters < 1 || colour_model.clusters > kMaxColourModelClusters) {
        out_of_range("colour_model.clusters", text_of(colour_model.clusters), "must be in [1, ",
                     kMaxColourModelClusters, "]");
    }
    if (compositing_radix < 2 || compositing_radix > 64) {
        out_of_range("compositing_radix", text_of(compositing_radix), "must be in [2, 64]");
    }
    check_cost(*this);
}

}  // namespace insitu
