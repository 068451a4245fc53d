#include "light_field_error_budget.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "insitu/error.hpp"

namespace insitu::evaluation {
namespace {

constexpr float kEmptyAlpha = 0.02f, kShownAlpha = 0.1f;

double psnr_of(double summed, std::size_t pixels) {
    const double mse = summed / (3.0 * static_cast<double>(pixels));
    return std::min(100.0, -10.0 * std::log10(std::max(mse, 1e-10)));
}

// Whether pixel (x, y), which the truth shows, lies within the band of a pixel it leaves empty.
bool near_outline(const std::vector<char>& empty, int width, int height, int x, int y) {
    const int reach = static_cast<int>(std::ceil(kSilhouetteBandPixels));
    const double band2 = kSilhouetteBandPixels * kSilhouetteBandPixels;
    for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
            if (dx * dx + dy * dy > band2) continue;
            if (empty[static_cast<std::size_t>(qy) * width + qx] != 0) return true;
        }
    }
    return false;
}

void check_pair(const char* what, const Image& truth, const Image& frame) {
    if (truth.width != frame.width || truth.height != frame.height || truth.channels != 4 ||
        frame.channels != 4) {
        fail<InvalidArgument>(what, ": ", truth, " against ", frame, " (need RGBA, one size)");
    }
}

// Each pixel's class (error_budget's rules) and squared error over premultiplied RGB, calling
// `visit(p, class, squared)` for every pixel p.
template <typename Visit>
void classify(const Image& truth, const Image& frame, Visit&& visit) {
    const int width = truth.width, height = truth.height;
    std::vector<char> empty(truth.pixel_count());
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        empty[p] = truth.pixels[4 * p + 3] < kEmptyAlpha ? 1 : 0;
    }
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * width + x;
            const float truth_alpha = truth.pixels[4 * p + 3], alpha = frame.pixels[4 * p + 3];
            PixelClass c = kInterior;
            if (empty[p] != 0) {
                c = alpha > kShownAlpha ? kGhost : kEmpty;
            } else if (truth_alpha > kShownAlpha && alpha < kEmptyAlpha) {
                c = kCrack;
            } else if (near_outline(empty, width, height, x, y)) {
                c = kSilhouette;
            }
            double squared = 0.0;
            for (int k = 0; k < 3; ++k) {
                const double d =
                    static_cast<double>(frame.pixels[4 * p + k]) - truth.pixels[4 * p + k];
                squared += d * d;
            }
            visit(p, c, squared);
        }
    }
}

}  // namespace

double ErrorBudget::psnr() const {
    return psnr_of(total, pixel_count);
}

double ErrorBudget::share(int c) const {
    return total > 0.0 ? error[static_cast<std::size_t>(c)] / total : 0.0;
}

double ErrorBudget::psnr_without(int c) const {
    return psnr_of(std::max(total - error[static_cast<std::size_t>(c)], 0.0), pixel_count);
}

ErrorBudget error_budget(const Image& truth, const Image& frame) {
    check_pair("error_budget", truth, frame);
    ErrorBudget budget;
    budget.pixel_count = truth.pixel_count();
    classify(truth, frame, [&](std::size_t, PixelClass c, double squared) {
        budget.error[c] += squared;
        budget.pixels[c] += 1;
        budget.total += squared;
    });
    return budget;
}

Image error_classes_image(const Image& truth, const Image& frame) {
    check_pair("error_classes_image", truth, frame);
    constexpr std::array<std::array<float, 3>, kPixelClasses> kColours{{{0.6f, 0.6f, 0.6f},
                                                                        {0.2f, 0.4f, 1.0f},
                                                                        {1.0f, 0.1f, 0.1f},
                                                                        {1.0f, 0.9f, 0.1f},
                                                                        {0.1f, 1.0f, 0.2f}}};
    Image out(truth.width, truth.height, 4, 1.0f);
    classify(truth, frame, [&](std::size_t p, PixelClass c, double squared) {
        const float strength = static_cast<float>(std::min(1.0, 4.0 * std::sqrt(squared / 3.0)));
        for (int k = 0; k < 3; ++k) {
            out.pixels[4 * p + k] =
                std::min(1.0f, 0.25f * truth.pixels[4 * p + k] + strength * kColours[c][k]);
        }
    });
    return out;
}

double mean_abs_percent(const Image& truth, const Image& frame) {
    double sum = 0.0;
    for (std::size_t p = 0; p < truth.pixel_count(); ++p) {
        for (int c = 0; c < 3; ++c)
            sum += std::abs(truth.pixels[4 * p + c] - frame.pixels[4 * p + c]);
    }
    return 100.0 * sum / (3.0 * static_cast<double>(truth.pixel_count()));
}

}  // namespace insitu::evaluation
