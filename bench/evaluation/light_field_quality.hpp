#pragma once
// Light fields that hold (issue 41): 42-camera light fields at 256^2 maps through the
// archive and the Explorer, from the light-field section's 30 random views against the ground
// truth: mean error, mean and worst PSNR (and which view), and cracks, the measure (the
// truth's alpha > 0.1 where the frame's < 0.02) as a share of the view's pixels, mean and worst.
// Writes light_field_cracks.csv and, besides, the stored view turned 20 degrees as PNGs (frame
// and truth) to look at.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "scenes.hpp"

namespace insitu::evaluation {

/// One step's light field of `scene` in an archive at `path`, as the Instrument writes it (the
/// archive's codec quantises the depth as a reader sees it), with the stored view `image`^2;
/// `light_field` as captured with `request`. Returns the light field's stored bytes.
std::uintmax_t write_light_field_archive(const Scene& scene, ProxyRenderer& renderer,
                                         const LightFieldRequest& request, LightField light_field,
                                         const std::string& path, int image);

void section_light_field_cracks(const std::vector<const Scene*>& scenes, bool smoke,
                                const std::filesystem::path& out,
                                const std::filesystem::path& scratch, int image);

/// Bytes against accuracy (issue 41 item 3): one attenuation light field of 42 cameras at 256^2
/// stored with its attenuation maps at full size and subsampled by 2 and 4, and its colour
/// lossless or lossy (DWA levels 45 and 100), each through the archive and the Explorer from the
/// same 30 random views, unedited and with held-out opacity edits, against the ground truth;
/// with the bytes of the same capture stored without attenuation. Writes light_field_bytes.csv.
void section_light_field_bytes(const std::vector<const Scene*>& scenes, bool smoke,
                               const std::filesystem::path& out,
                               const std::filesystem::path& scratch, int image);

/// The default rig's choice (bench/RESULTS.md, "The default rig: 162 cameras at 128²"): per rig
/// (42 cameras at 256^2 and 162 at 128^2, 42 at 192^2 and 162 at 96^2), the configuration's
/// default light field (attenuation, rims) captured, timed per camera against a proxy pass of
/// the same pixels (the bound), stored through the archive and made into the page's
/// payload. Writes light_field_rig.csv.
void section_light_field_rig(const std::vector<const Scene*>& scenes, bool smoke,
                             const std::filesystem::path& out, const std::filesystem::path& scratch,
                             int image);

}  // namespace insitu::evaluation
