#include "volume_field.hpp"

#include <cmath>
#include <cstdio>

#include "insitu/error.hpp"
#include "median_time.hpp"
#include "representation/volume/zfp_volume.hpp"

namespace insitu::evaluation {

std::string ZfpSetting::label() const {
    char text[48];
    std::snprintf(text, sizeof text, "%s %g", mode == Mode::accuracy ? "accuracy" : "rate", value);
    return text;
}

std::vector<ZfpSetting> zfp_settings(bool smoke) {
    using Mode = ZfpSetting::Mode;
    if (smoke) return {{Mode::accuracy, 1e-2}, {Mode::accuracy, 1e-3}, {Mode::rate, 1.0}};
    std::vector<ZfpSetting> settings;
    for (const double r : {3e-1, 1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4}) {
        settings.push_back({Mode::accuracy, r});
    }
    for (const double rate : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0})
        settings.push_back({Mode::rate, rate});
    return settings;
}

CompressedField compress_field(const Scene& scene, const ZfpSetting& setting, int repeats) {
    if (!(setting.value > 0.0) || !std::isfinite(setting.value)) {
        fail<InvalidArgument>("ZFP ", setting.label(), ": needs a positive finite value");
    }
    CompressedField result;
    result.decoded = scene.volume;
    archive_format::ZfpParameters parameters;
    if (setting.mode == ZfpSetting::Mode::accuracy) {
        result.tolerance = setting.value * (scene.value_max - scene.value_min);
        parameters = {VolumeMode::accuracy, result.tolerance, 0.0, 1};
    } else {
        parameters = {VolumeMode::rate, 0.0, setting.value, 1};
    }
    // The archive's own codec, as the writer's thread runs it: the bytes are the file's.
    archive_format::EncodedVolumeBlock encoded;
    result.compress_ms = bench::median_ms(repeats, [&] {
        encoded = archive_format::encode_volume_block(scene.volume.values.data(), scene.volume.dims,
                                                      parameters);
    });
    result.bytes = encoded.stream.size() + encoded.mask.size();
    const std::vector<char> stream(encoded.stream.begin(), encoded.stream.end());
    const std::vector<char> mask(encoded.mask.begin(), encoded.mask.end());
    result.decompress_ms = bench::median_ms(repeats, [&] {
        result.decoded.values = archive_format::decode_volume_block(
            stream, mask, scene.volume.dims, encoded.nonfinite, "evaluation");
    });
    return result;
}

}  // namespace insitu::evaluation
