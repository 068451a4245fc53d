#pragma once
// Image and depth error metrics of the evaluation harness (bench/evaluate), implemented once and
// shared by the harness, the VTK peer program and tests/failure_modes_test.cpp.
//
//  * PSNR on premultiplied RGBA composited over black: over black, the composited colour is the
//    premultiplied RGB itself, so PSNR = 10 log10(1 / MSE) over the R, G, B values of all pixels,
//    peak 1. MSE is floored at 1e-10 so identical images give a finite 100 dB.
//  * SSIM (Wang, Bovik, Sheikh, Simoncelli 2004) on luminance Y = 0.2126 R + 0.7152 G + 0.0722 B
//    of the same composited colour, with the paper's 11x11 Gaussian window (sigma 1.5),
//    K1 = 0.01, K2 = 0.03, dynamic range 1; the mean over every window position fully inside
//    the image.
//  * Max absolute error over all channels (RGBA).
//  * Pearson correlation of two depth images over the pixels finite in both (seed 000 §4.4,
//    Fig. 6a: "the correlation between the depth images generated from 3D data versus the depth
//    images reconstructed").
//  * Mask coverage: of the pixels that went wrong (error above a threshold), the fraction the
//    confidence mask flagged (confidence < 1).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/error.hpp"

namespace insitu::evaluation {

constexpr double kPsnrCapDb = 100.0;  ///< PSNR of identical images (MSE floor 1e-10)

inline void require_same_size(const Image& a, const Image& b, int min_channels, const char* what) {
    if (a.width != b.width || a.height != b.height || a.channels < min_channels ||
        b.channels < min_channels) {
        fail<InvalidArgument>(what, ": images ", a.width, "x", a.height, "x", a.channels, " and ",
                              b.width, "x", b.height, "x", b.channels,
                              " (need equal sizes, >= ", min_channels, " channels)");
    }
}

/// Mean squared error over the premultiplied RGB of two RGBA images (composited over black):
/// the core's definition (insitu/core/image.hpp), which an error budget measures in situ.
using insitu::mse_rgb;

/// Sum of squared differences over premultiplied RGB (seed 000 Fig. 13's "SSD").
inline double ssd_rgb(const Image& a, const Image& b) {
    return mse_rgb(a, b) * 3.0 * static_cast<double>(a.pixel_count());
}

/// NaN when either image holds a NaN (garbage must not read as a perfect match); at most
/// kPsnrCapDb.
inline double psnr_db(const Image& a, const Image& b) {
    return psnr_rgb_db(a, b);
}

/// PSNR in dB of premultiplied RGB against `truth`, peak 1, over the pixels either image covers
/// (alpha > 0): empty background would otherwise inflate it. +inf when neither covers any pixel;
/// MSE floored at 1e-20, so it is not capped at kPsnrCapDb. Both images RGBA of one size.
inline double psnr_covered_db(const Image& image, const Image& truth) {
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        if (!(truth.pixels[4 * p + 3] > 0.0f) && !(image.pixels[4 * p + 3] > 0.0f)) continue;
        for (int c = 0; c < 3; ++c) {
            const double d = double(image.pixels[4 * p + c]) - truth.pixels[4 * p + c];
            sum += d * d;
        }
        count += 3;
    }
    return count == 0 ? INFINITY : -10.0 * std::log10(std::max(sum / count, 1e-20));
}

inline double max_abs_error(const Image& a, const Image& b) {
    require_same_size(a, b, 1, "max_abs_error");
    if (a.channels != b.channels) {
        fail<InvalidArgument>("max_abs_error: ", a.channels, " and ", b.channels, " channels");
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        const double d = std::abs(static_cast<double>(a.pixels[i]) - b.pixels[i]);
        if (std::isnan(d)) return d;
        worst = std::max(worst, d);
    }
    return worst;
}

/// Luminance of the premultiplied colour composited over black, one value per pixel.
inline std::vector<double> luminance(const Image& rgba) {
    std::vector<double> y(rgba.pixel_count());
    for (std::size_t p = 0; p < y.size(); ++p) {
        const float* c = &rgba.pixels[p * rgba.channels];
        y[p] = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    }
    return y;
}

inline double ssim_luminance(const Image& a, const Image& b) {
    require_same_size(a, b, 3, "ssim_luminance");
    constexpr int kRadius = 5;  // 11x11 window
    constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
    const int w = a.width, h = a.height;
    if (w < 2 * kRadius + 1 || h < 2 * kRadius + 1) {
        fail<InvalidArgument>("ssim_luminance: image ", w, "x", h, " is smaller than the ",
                              2 * kRadius + 1, "x", 2 * kRadius + 1, " window");
    }
    double weights[2 * kRadius + 1];
    double total = 0.0;
    for (int i = -kRadius; i <= kRadius; ++i) {
        weights[i + kRadius] = std::exp(-0.5 * i * i / (kSigma * kSigma));
        total += weights[i + kRadius];
    }
    for (double& weight : weights) weight /= total;
    const std::vector<double> x = luminance(a), y = luminance(b);
    // Separable Gaussian filtering of x, y, x^2, y^2, xy: rows first ("valid" columns only),
    // then columns over the valid rows.
    const int vw = w - 2 * kRadius, vh = h - 2 * kRadius;
    std::vector<double> rows(static_cast<std::size_t>(5) * h * vw, 0.0);
    for (int r = 0; r < h; ++r) {
        for (int c = 0; c < vw; ++c) {
            double s[5] = {0, 0, 0, 0, 0};
            for (int k = 0; k <= 2 * kRadius; ++k) {
                const std::size_t p = static_cast<std::size_t>(r) * w + c + k;
                const double wk = weights[k];
                s[0] += wk * x[p];
                s[1] += wk * y[p];
                s[2] += wk * x[p] * x[p];
                s[3] += wk * y[p] * y[p];
                s[4] += wk * x[p] * y[p];
            }
            for (int m = 0; m < 5; ++m) rows[(static_cast<std::size_t>(m) * h + r) * vw + c] = s[m];
        }
    }
    double sum = 0.0;
    for (int r = 0; r < vh; ++r) {
        for (int c = 0; c < vw; ++c) {
            double s[5] = {0, 0, 0, 0, 0};
            for (int k = 0; k <= 2 * kRadius; ++k) {
                for (int m = 0; m < 5; ++m) {
                    s[m] += weights[k] * rows[(static_cast<std::size_t>(m) * h + r + k) * vw + c];
                }
            }
            const double mx = s[0], my = s[1];
            const double vx = s[2] - mx * mx, vy = s[3] - my * my, cxy = s[4] - mx * my;
            sum += ((2 * mx * my + kC1) * (2 * cxy + kC2)) /
                   ((mx * mx + my * my + kC1) * (vx + vy + kC2));
        }
    }
    return sum / (static_cast<double>(vw) * vh);
}

struct DepthCorrelation {
    double coefficient = 0.0;  ///< Pearson r over `pixels`; 0 when undefined (see below)
    std::int64_t pixels = 0;   ///< pixels finite in both images
    bool defined = false;      ///< false when fewer than 2 pixels or a constant image
};

/// Pearson correlation of two 1-channel depth images over pixels finite in both.
inline DepthCorrelation depth_correlation(const Image& a, const Image& b) {
    require_same_size(a, b, 1, "depth_correlation");
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    std::int64_t n = 0;
    for (std::size_t p = 0; p < a.pixel_count(); ++p) {
        const double u = a.pixels[p * a.channels], v = b.pixels[p * b.channels];
        if (!std::isfinite(u) || !std::isfinite(v)) continue;
        ++n;
        sa += u;
        sb += v;
        saa += u * u;
        sbb += v * v;
        sab += u * v;
    }
    DepthCorrelation result;
    result.pixels = n;
    if (n < 2) return result;
    const double cov = sab - sa * sb / n, va = saa - sa * sa / n, vb = sbb - sb * sb / n;
    if (!(va > 0.0) || !(vb > 0.0)) return result;
    result.coefficient = cov / std::sqrt(va * vb);
    result.defined = true;
    return result;
}

/// Per-pixel error of two RGBA images: the largest absolute difference over premultiplied RGB.
inline std::vector<double> pixel_errors_rgb(const Image& a, const Image& b) {
    require_same_size(a, b, 3, "pixel_errors_rgb");
    std::vector<double> error(a.pixel_count());
    for (std::size_t p = 0; p < error.size(); ++p) {
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(static_cast<double>(a.pixels[p * a.channels + c]) -
                                             b.pixels[p * b.channels + c]));
        }
        error[p] = worst;
    }
    return error;
}

/// Per-pixel error of two depth images (world units): |a - b| where both are finite, +inf where
/// exactly one is (a surface missing or invented), 0 where neither is.
inline std::vector<double> pixel_errors_depth(const Image& a, const Image& b) {
    require_same_size(a, b, 1, "pixel_errors_depth");
    std::vector<double> error(a.pixel_count());
    for (std::size_t p = 0; p < error.size(); ++p) {
        const double u = a.pixels[p * a.channels], v = b.pixels[p * b.channels];
        const bool fu = std::isfinite(u), fv = std::isfinite(v);
        error[p] =
            fu && fv ? std::abs(u - v) : (fu != fv ? std::numeric_limits<double>::infinity() : 0.0);
    }
    return error;
}

struct MaskCoverage {
    std::int64_t high_error_pixels = 0;  ///< pixels with error > threshold
    std::int64_t flagged = 0;            ///< of those, pixels the mask flags
    std::int64_t pixels = 0;             ///< all pixels
    std::int64_t good_pixels = 0;        ///< counted pixels with error <= threshold
    std::int64_t good_flagged = 0;       ///< of those, pixels the mask flags
    /// flagged / high_error_pixels; 1 when no pixel went wrong (nothing needed flagging).
    double flagged_fraction() const {
        return high_error_pixels == 0 ? 1.0 : static_cast<double>(flagged) / high_error_pixels;
    }
    double high_error_fraction() const {
        return pixels == 0 ? 0.0 : static_cast<double>(high_error_pixels) / pixels;
    }
    /// good_flagged / good_pixels: the mask's false alarms; 0 without good pixels.
    double good_flagged_fraction() const {
        return good_pixels == 0 ? 0.0 : static_cast<double>(good_flagged) / good_pixels;
    }
};

/// How much of what went wrong (error > threshold) the 1-channel confidence mask flagged, a
/// pixel being flagged where its confidence is below `flag_below`, and how many right pixels it
/// flagged too: those where `counted` is nonzero (all when null; e.g. the pixels either image
/// covers, so that empty background does not dilute the false alarms).
inline MaskCoverage mask_coverage(const std::vector<double>& errors, const Image& confidence,
                                  double threshold, double flag_below = 1.0,
                                  const std::vector<char>* counted = nullptr) {
    if (confidence.pixel_count() != errors.size() || confidence.channels < 1 ||
        (counted && counted->size() != errors.size())) {
        fail<InvalidArgument>("mask_coverage: ", errors.size(), " errors and a ", confidence.width,
                              "x", confidence.height, "x", confidence.channels, " mask");
    }
    MaskCoverage coverage;
    coverage.pixels = static_cast<std::int64_t>(errors.size());
    for (std::size_t p = 0; p < errors.size(); ++p) {
        const bool flagged = confidence.pixels[p * confidence.channels] < flag_below;
        if (!(errors[p] > threshold) && !std::isnan(errors[p])) {
            if (counted && !(*counted)[p]) continue;
            ++coverage.good_pixels;
            if (flagged) ++coverage.good_flagged;
            continue;
        }
        ++coverage.high_error_pixels;
        if (flagged) ++coverage.flagged;
    }
    return coverage;
}

/// The pixels either of two RGBA images covers (alpha above 1e-3).
inline std::vector<char> covered_pixels(const Image& a, const Image& b) {
    require_same_size(a, b, 4, "covered_pixels");
    std::vector<char> covered(a.pixel_count());
    for (std::size_t p = 0; p < covered.size(); ++p) {
        covered[p] = a.pixels[p * a.channels + 3] > 1e-3f || b.pixels[p * b.channels + 3] > 1e-3f;
    }
    return covered;
}

}  // namespace insitu::evaluation
