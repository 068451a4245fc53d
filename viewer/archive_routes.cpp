#include "archive_routes.hpp"

#include <algorithm>
#include <mutex>
#include <nlohmann/json.hpp>
#include <vector>

#include "http_boundary.hpp"
#include "insitu/archive/archive_description.hpp"
#include "insitu/core/image.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "request_parameters.hpp"

namespace insitu::viewer {
namespace {

using json = nlohmann::json;

/// Per field, the union of the steps' value ranges (the manifest's per-step histograms): the
/// range "same colours at every step" spreads one function over.
json run_value_ranges(const json& manifest) {
    json ranges = json::object();
    for (const json& step : manifest.at("steps")) {
        for (const json& field : step.value("fields", json::array())) {
            const json& histogram = field.value("histogram", json::object());
            if (!histogram.value("min", json()).is_number() ||
                !histogram.value("max", json()).is_number()) {
                continue;  // a field of no finite values at this step
            }
            const double lo = histogram.at("min").get<double>();
            const double hi = histogram.at("max").get<double>();
            json& range = ranges[field.at("field").get<std::string>()];
            range = range.is_null() ? json{{"min", lo}, {"max", hi}}
                                    : json{{"min", std::min(lo, range["min"].get<double>())},
                                           {"max", std::max(hi, range["max"].get<double>())}};
        }
    }
    return ranges;
}

/// The archive's description for the page: describe_archive, each step's time, the archive's
/// name, the function the editor starts from and the run's value range per field.
std::string archive_description(const ArchiveReader& reader, const std::string& name) {
    const std::vector<std::int64_t> steps = reader.steps();
    json description = describe_archive(reader);
    json timeline = json::array();
    for (const std::int64_t step : steps) {
        timeline.push_back({{"step", step}, {"time", reader.entry(step, 0).time}});
    }
    description["timeline"] = timeline;
    description["name"] = name;
    description["value_ranges"] = run_value_ranges(reader.manifest());
    // The editor starts from the first step's function ("auto" makes one per step; /api/step
    // says each step's).
    if (!steps.empty()) {
        description["transfer_function"] = reader.transfer_function(steps.front(), 0).to_json();
    }
    return description.dump();
}

/// A summary for the editor, not per-pixel synthesis: a_j summed over the stored image (Eq. 7),
/// as the mean per pixel.
std::vector<double> mean_attenuation(const Image& a, int intervals) {
    std::vector<double> sums(intervals, 0.0);
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        for (int j = 0; j < a.channels; ++j) {
            sums[j] += a.pixels[p * a.channels + j];
        }
    }
    for (double& sum : sums) sum /= static_cast<double>(a.pixel_count());
    return sums;
}

/// What /api/step says of (step, view) but its light-field segments.
json step_description(const ArchiveReader& reader, const StepKey& key) {
    const ProxyFrame frame = reader.load(key.step, key.view);
    const Camera& camera = frame.camera;
    json info{{"step", key.step},
              {"view", key.view},
              {"field", reader.entry(key.step, key.view).field},
              {"time", reader.entry(key.step, key.view).time},
              {"size", {camera.width(), camera.height()}},
              {"projection", to_string(camera.projection())},
              {"azimuth", camera.azimuth_deg()},
              {"elevation", camera.elevation_deg()},
              {"isovalues", frame.isovalues},
              {"depth_layers", frame.depth_layers.size()},
              {"colour_model", frame.colour_model.has_value()},
              {"camera", camera.to_json()},
              {"transfer_function", reader.transfer_function(key.step, key.view).to_json()}};
    // The field's values at the step, for the editor's histogram (older archives: none).
    const std::optional<FieldSummaryRecord> summary =
        reader.field_summary(key.step, reader.entry(key.step, key.view).field);
    if (summary) {
        info["histogram"] = summary->histogram.to_json();
        info["nonfinite_samples"] = summary->nonfinite_samples;
    }
    // The step's compressed field of the view's field, which the page may ray-march
    // (/api/volume; the frame's recipe says when).
    for (const ArchivedVolume& volume : reader.volumes(key.step)) {
        if (volume.field != reader.entry(key.step, key.view).field) continue;
        info["volume"] = {{"codec", volume.codec},         {"mode", to_string(volume.mode)},
                          {"tolerance", volume.tolerance}, {"rate", volume.rate},
                          {"dims", volume.dims},           {"bytes", volume.bytes}};
    }
    if (frame.intervals) {
        const IntervalSet& intervals = *frame.intervals;
        info["intervals"] = intervals.edges();
        info["interval_colours"] =
            interval_colours(reader.transfer_function(key.step, key.view), intervals);
        if (frame.attenuation.channels == intervals.count()) {
            info["mean_attenuation"] = mean_attenuation(frame.attenuation, intervals.count());
        }
    }
    return info;
}

}  // namespace

void ArchiveRoutes::archive(const httplib::Request& request, httplib::Response& response) {
    if (!request.params.empty()) throw HttpError(400, "/api/archive takes no parameters");
    std::lock_guard<std::mutex> lock(archive_.mutex());
    archive_.refresh_locked();
    if (!description_ || description_->first != archive_.generation_locked()) {
        const ArchiveReader& reader = archive_.reader_locked();
        // describe_archive reads the first step of each view.
        const std::vector<std::int64_t> steps = reader.steps();
        if (!steps.empty()) {
            for (int v = 0; v < reader.view_count(); ++v) {
                archive_.require_files_inside_locked(steps.front(), v);
            }
        }
        description_.emplace(archive_.generation_locked(),
                             archive_description(reader, archive_.root().filename().string()));
    }
    response.set_header("Cache-Control", "no-store");
    response.set_content(description_->second, "application/json");
}

void ArchiveRoutes::step_info(const httplib::Request& request, httplib::Response& response) {
    const StepKey key = step_key(request, archive_);
    std::lock_guard<std::mutex> lock(archive_.mutex());
    auto found = step_infos_.find(key);
    if (found == step_infos_.end()) {
        archive_.require_files_inside_locked(key.step, key.view);
        json info = step_description(archive_.reader_locked(), key);
        // How many faders the page shows (0: the step has no light field of the field).
        info["light_field_segments"] = archive_.light_field_segments_locked(key);
        if (step_infos_.size() >= kMaxStepInfos) step_infos_.clear();
        found = step_infos_.emplace(key, info.dump()).first;
    }
    response.set_content(found->second, "application/json");
}

}  // namespace insitu::viewer
