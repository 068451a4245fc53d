#pragma once
// Fields and transfer functions of the evaluation harness (bench/evaluate): analytic fields,
// Gray-Scott timesteps and raw files given on the command line, and one family of transfer
// functions defined over each field's normalised value x = (v - min) / (max - min), so that
// every field is shown, edited and recoloured the same way.
#include <cstdint>
#include <string>
#include <vector>

#include "insitu/core/intervals.hpp"
#include "insitu/core/transfer_function.hpp"
#include "insitu/testing/analytic_fields.hpp"

namespace insitu::evaluation {

/// A field the harness evaluates on: samples it owns, and its finite value range.
struct Scene {
    std::string name;
    SampledVolume volume;
    double value_min = 0.0;
    double value_max = 1.0;
    /// Opacity unit length (world units): 1/64 of the largest extent, so a field looks alike
    /// whatever its size.
    double unit_length = 1.0;
};

/// Fills value_min/max and unit_length from the samples; InvalidArgument for a field with no
/// finite sample or a constant one.
Scene make_scene(std::string name, SampledVolume volume);

/// The v field of the Gray-Scott mini-app after each of `snapshot_steps` (ascending), on a
/// size^3 grid.
std::vector<Scene> gray_scott_scenes(int size, const std::vector<int>& snapshot_steps);

/// A raw file of dims[0] x dims[1] x dims[2] samples (x fastest) of `type`, native byte order.
/// IoError names the file when it cannot be read or has the wrong size.
Scene load_raw(const std::string& path, Index3 dims, ScalarType type);

/// How a transfer function of the family differs from the stored one.
struct TfSpec {
    /// Opacity scale of the low band (x < 0.5: the outer, thinner structures of the scenes) and
    /// of the high band (x >= 0.5: their cores). The stored function has both 1.
    double low_scale = 1.0;
    double high_scale = 1.0;
    /// Uniform opacity scale on top of the bands.
    double scale = 1.0;
    enum class Colours {
        ramp,       ///< the stored colours: blue - cyan - yellow - red, varying within intervals
        other,      ///< a recolouring: purple - green - orange, varying within intervals
        piecewise,  ///< a recolouring constant per interval of `intervals` (steps at the edges)
    } colours = Colours::ramp;
    int intervals = 16;  ///< for Colours::piecewise: the uniform intervals it is constant over
};

/// Opacity per unit length rises from 0 at x = 0.15 to its largest at x = 1; control points at
/// multiples of 1/16 of the range (every edge of 1, 2, 4, 8, 16, 32, 64 uniform intervals is
/// one), and a step between the bands at x = 0.5, so band scales are constant per interval.
TransferFunction make_tf(const Scene& scene, const TfSpec& spec = {});

/// A sharp function the run never saw (issue 40): `peaks` narrow peaks at x = 0.3 .. 0.7, each
/// `width` of the value range wide at its base (opacity rising linearly to 0.8 per unit length at
/// its centre), a colour of its own each, nothing between them. Where the field's error moves a
/// value across a peak, the colour moves: it shows what a compressed field's tolerance costs.
TransferFunction make_sharp_tf(const Scene& scene, int peaks = 3, double width = 0.02);

/// L uniform intervals over the scene's value range (what the Instrument chooses by default).
IntervalSet scene_intervals(const Scene& scene, int count);

/// Isovalues of `count` depth layers at x = 0.3 .. 0.75, evenly; layer 0 is always x = 0.3.
std::vector<double> scene_layers(const Scene& scene, int count);

/// Opacity edits held out from training, in the training range of 3 training images
/// (seed 000 Fig. 13: progressively showing the inner structures).
std::vector<TfSpec> held_out_edits(int count);
/// The training transfer functions for `count` training images (1..3): the stored one, then the
/// low band faded, then the high band faded.
std::vector<TfSpec> training_specs(int count);

}  // namespace insitu::evaluation
