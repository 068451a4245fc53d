#pragma once
// What light-field reconstruction (light_field_reconstruction.hpp) does besides its pixels: the
// checks of its input (settings, and each camera's images against the rig and the light
// field's segment and interval counts) and its workers over the target's rows.
#include <functional>
#include <vector>

#include "insitu/explore/light_field_reconstruction.hpp"

namespace insitu::detail {

constexpr int kMinSearchSteps = 4;
constexpr int kMaxSearchSteps = 4096;

/// InvalidArgument naming search_steps out of range, a bad opacity scale, or more scales than
/// the light field's `segments`.
void check_settings(const LightFieldReconstructionSettings& settings, int segments);

/// The images of each rig camera (null where the light field lacks it), after checking that
/// every image has the rig's map size and the light field's segment and interval counts.
std::vector<const LightFieldImages*> camera_table(const LightField& light_field, int segments,
                                                  int intervals);

/// Workers over `height` rows: hardware_concurrency of them, at least 1, at most one a row.
unsigned row_workers(int height);
/// row(worker, y) for every y in [0, height), rows taken in turn by row_workers(height) threads
/// (worker: the thread's index); the first exception a row throws stops the others after their
/// row and is rethrown.
void parallel_rows(int height, const std::function<void(unsigned worker, int y)>& row);

}  // namespace insitu::detail
