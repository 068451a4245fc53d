#pragma once
// Where a frame's squared error lies (issue 41): each pixel's squared error over premultiplied
// RGB (what psnr_db averages) by the class of pixel it falls in, so that a fix aimed at one class
// can be priced in dB before it is written: the frame's PSNR with that class's error removed
// (its pixels replaced by the truth's).
#include <array>
#include <cstddef>

#include "insitu/core/image.hpp"

namespace insitu::evaluation {

/// The classes, first match wins: in the truth's empty space (alpha < 0.02) a ghost where the
/// frame shows something (alpha > 0.1), else empty; where the truth shows something, a crack
/// (the truth's alpha > 0.1, the frame's < 0.02: the cracks section's measure), else the
/// silhouette band (within kSilhouetteBandPixels of a pixel empty in the truth), else interior.
enum PixelClass { kEmpty, kGhost, kCrack, kSilhouette, kInterior, kPixelClasses };
inline constexpr std::array<const char*, kPixelClasses> kPixelClassNames{"empty", "ghost", "crack",
                                                                         "silhouette", "interior"};
inline constexpr double kSilhouetteBandPixels = 2.0;

struct ErrorBudget {
    std::size_t pixel_count = 0;
    double total = 0.0;                               ///< summed squared error
    std::array<double, kPixelClasses> error{};        ///< by class, summing to `total`
    std::array<std::size_t, kPixelClasses> pixels{};  ///< by class

    /// As psnr_db (MSE over 3 channels, floored at 1e-10, capped at 100 dB).
    double psnr() const;
    /// Class c's share of the summed squared error (0 where there is none).
    double share(int c) const;
    /// The PSNR with class c's error removed.
    double psnr_without(int c) const;
};

/// `truth` and `frame`: RGBA, premultiplied, one size.
ErrorBudget error_budget(const Image& truth, const Image& frame);

/// Where a frame's error lies, to look at: each pixel the truth's colour at a quarter, plus its
/// class's colour (empty grey, ghost blue, crack red, silhouette yellow, interior green) scaled by
/// its error (root mean square over premultiplied RGB, times 4, at most 1). Opaque RGBA.
Image error_classes_image(const Image& truth, const Image& frame);

/// The light-field sections' mean error: mean absolute difference over premultiplied RGB and
/// every pixel, in percent of full scale.
double mean_abs_percent(const Image& truth, const Image& frame);

}  // namespace insitu::evaluation
