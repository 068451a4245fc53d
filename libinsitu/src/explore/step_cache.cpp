#include "insitu/explore/step_cache.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <utility>

#include "insitu/archive/archive_description.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/transfer_function_edit.hpp"

namespace insitu {

StepCache::StepCache(const std::string& archive_path, ArchiveOmissions omitted)
    : path_(archive_path),
      omitted_(omitted),
      archive_(std::make_unique<ArchiveReader>(ArchiveReader(archive_path).without(omitted))) {}

void StepCache::refresh() {
    // Steps are immutable once the manifest names them, so the cached frames stay valid.
    archive_ = std::make_unique<ArchiveReader>(ArchiveReader(path_).without(omitted_));
    attenuation_resolution_.reset();
}

double StepCache::stored_attenuation_resolution() {
    if (!attenuation_resolution_) {
        // Half, the coarser, where the configuration cannot be read: the trust then errs on the
        // side of flagging.
        StoragePrecision precision = StoragePrecision::half;
        try {
            precision = archive_->configuration().precision;
        } catch (const ParseError&) {
        }
        attenuation_resolution_ = precision == StoragePrecision::half ? kHalfAttenuationResolution
                                                                      : kFloatAttenuationResolution;
    }
    return *attenuation_resolution_;
}

const CachedStep& StepCache::load(std::int64_t step, int view) {
    for (auto it = steps_.begin(); it != steps_.end(); ++it) {
        if (it->step == step && it->view == view) {
            steps_.splice(steps_.begin(), steps_, it);
            return steps_.front();
        }
    }
    // entry() raises InvalidArgument naming a step or view the archive lacks.
    archive_->entry(step, view);
    CachedStep cached;
    cached.step = step;
    cached.view = view;
    const nlohmann::json& manifest = archive_->manifest();
    if (has_perspective(manifest, step, view, false)) cached.single = archive_->load(step, view);
    if (has_perspective(manifest, step, view, true)) {
        cached.multi = archive_->load(step, view, true);
    }
    steps_.push_front(std::move(cached));
    // A few frames: enough to scrub back and forth without re-reading, bounded memory.
    constexpr std::size_t kCachedFrames = 4;
    if (steps_.size() > kCachedFrames) steps_.pop_back();
    return steps_.front();
}

const LightField* StepCache::load_light_field(std::int64_t step, const std::string& field,
                                              const std::vector<int>& cameras) {
    const std::vector<ArchivedLightField> available = archive_->light_fields(step);
    const bool listed =
        std::any_of(available.begin(), available.end(),
                    [&](const ArchivedLightField& lf) { return lf.field == field; });
    if (!listed) return nullptr;
    if (!light_field_ || light_field_->step != step || light_field_->field != field) {
        light_field_ =
            CachedLightField{step, field, archive_->load_light_field(step, field, cameras)};
        return &light_field_->light_field;
    }
    LightField& cached = light_field_->light_field;
    std::vector<int> missing;
    for (int k : cameras) {
        if (cached.find(k) == nullptr) missing.push_back(k);
    }
    if (!missing.empty()) {
        LightField more = archive_->load_light_field(step, field, missing);
        for (LightFieldImages& images : more.cameras) cached.cameras.push_back(std::move(images));
        // Cameras the file lacks stay missing; asking again would re-read the file each frame,
        // so the reconstruction reports them instead.
    }
    return &cached;
}

const VolumeGrid* StepCache::load_volume(std::int64_t step, const std::string& field) {
    if (volume_ && volume_->first == step && volume_->second.field == field) {
        return &volume_->second;
    }
    const std::vector<ArchivedVolume> available = archive_->volumes(step);
    const bool listed =
        std::any_of(available.begin(), available.end(),
                    [&](const ArchivedVolume& volume) { return volume.field == field; });
    if (!listed) return nullptr;
    // One grid kept: the one being explored (a grid is the field's size; the next step's
    // replaces it).
    volume_.reset();
    volume_.emplace(step, archive_->load_volume(step, field));
    return &volume_->second;
}

}  // namespace insitu
