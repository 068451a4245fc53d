#pragma once
// The steps an Explorer shows (explorer.hpp, step 1): a view's proxies at a step and a field's
// light field, read from the archive on demand and kept, so that scrubbing back and forth and
// turning the view re-read nothing.
#include <cstdint>
#include <list>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "insitu/archive/archive_reader.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

/// The proxies of one (step, view).
struct CachedStep {
    std::int64_t step = 0;
    int view = 0;
    std::optional<ProxyFrame> single;  ///< at least one of the two is present
    std::optional<ProxyFrame> multi;
};

class StepCache {
public:
    /// Opens the archive (IoError/ParseError name the file).
    /// `omitted`: representations read as absent (ArchiveReader::without).
    explicit StepCache(const std::string& archive_path, ArchiveOmissions omitted = {});

    /// Re-reads the manifest so steps a running simulation wrote since appear.
    void refresh();
    const ArchiveReader& archive() const { return *archive_; }

    /// The proxies of (step, view); InvalidArgument names a step or view the archive lacks.
    const CachedStep& load(std::int64_t step, int view);
    /// The light field of (step, field) holding at least `cameras` (loaded on demand: a frame
    /// needs the cameras facing it, not all of them); null when the step has none for `field`.
    const LightField* load_light_field(std::int64_t step, const std::string& field,
                                       const std::vector<int>& cameras);
    /// The compressed field of (step, field), decoded (the last one asked is kept); null when the
    /// step has none of `field`.
    const VolumeGrid* load_volume(std::int64_t step, const std::string& field);
    /// How exactly the archive stores a_j, by its "precision" (EditTrustInputs); read once per
    /// refresh, on the first edit.
    double stored_attenuation_resolution();

private:
    /// One light field kept (they are large: cameras x map pixels x channels).
    struct CachedLightField {
        std::int64_t step = 0;
        std::string field;
        LightField light_field;
    };

    std::string path_;
    ArchiveOmissions omitted_;
    std::unique_ptr<ArchiveReader> archive_;
    std::list<CachedStep> steps_;  ///< most recently used first
    std::optional<CachedLightField> light_field_;
    std::optional<std::pair<std::int64_t, VolumeGrid>> volume_;
    std::optional<double> attenuation_resolution_;
};

}  // namespace insitu
