#pragma once
// How far a float stored as half (OpenEXR's HALF) may come back from itself: the tolerances the
// archive tests hold "precision": "half" round trips to.
namespace insitu::testing {

// Half keeps 10 explicit mantissa bits: round-to-nearest is within 2^-11 relative for normal
// values; below half's smallest normal (6.1e-5) the spacing is 2^-24, so half of that absolute.
constexpr double kHalfRelative = 1.0 / 2048.0;
constexpr double kHalfAbsolute = 1.0 / (1 << 25);

}  // namespace insitu::testing
