// Transfer-function edits from attenuation proxies (seed 000 §6): host side of
// kernels/explore/transfer_function_edit.cl, and the per-interval summaries of transfer functions.
#include "insitu/explore/transfer_function_edit.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "device/device_image.hpp"
#include "insitu/error.hpp"

namespace insitu {

namespace {

/// Opacity of an opaque point, so its extinction -ln(1 - a) stays finite (about 13.8).
constexpr double kMaxOpacity = 1.0 - 1e-6;
/// Sub-steps of Simpson's rule between two control points for the (non-polynomial) extinction.
constexpr int kExtinctionSubsteps = 64;

void require_1d(const TransferFunction& tf, const char* what) {
    if (tf.is_2d()) {
        fail<InvalidArgument>(what, ": ", tf,
                              " is 2D; per-interval summaries need a function of the value only");
    }
}

/// Where the function's pieces meet inside [low, high], with both ends: between consecutive
/// breakpoints it is linear.
std::vector<double> breakpoints(const TransferFunction& tf, double low, double high) {
    std::vector<double> points{low};
    for (const ControlPoint& point : tf.rows().front().points) {
        if (point.value > low && point.value < high) points.push_back(point.value);
    }
    points.push_back(high);
    return points;
}

/// Simpson's rule over [low, high] of f; exact for polynomials up to degree 3.
template <typename F>
double simpson(F f, double low, double high) {
    return (high - low) / 6.0 * (f(low) + 4.0 * f(0.5 * (low + high)) + f(high));
}

/// The integral over interval j of f(value); a zero-width interval gives f at its value (as the
/// "integral" of a point mass), so means stay defined.
template <typename F>
double integrate(const TransferFunction& tf, double low, double high, int substeps, F f) {
    if (!(high > low)) return f(low);
    const std::vector<double> points = breakpoints(tf, low, high);
    double sum = 0.0;
    for (std::size_t p = 0; p + 1 < points.size(); ++p) {
        const double width = (points[p + 1] - points[p]) / substeps;
        for (int s = 0; s < substeps; ++s) {
            sum += simpson(f, points[p] + s * width, points[p] + (s + 1) * width);
        }
    }
    return sum;
}

/// Mean extinction per world unit of `tf` over [low, high].
double mean_extinction(const TransferFunction& tf, double low, double high) {
    const double integral = integrate(tf, low, high, kExtinctionSubsteps, [&](double v) {
        const double opacity = std::min<double>(tf.evaluate(v).a, kMaxOpacity);
        return -std::log1p(-opacity);
    });
    const double width = high - low;
    return (width > 0.0 ? integral / width : integral) / tf.unit_length();
}

void check_same_size(const Image& image, const Image& reference, const char* what) {
    if (image.width != reference.width || image.height != reference.height ||
        image.channels != reference.channels) {
        fail<InvalidArgument>("estimate_attenuation: ", what, " is ", image.width, "x",
                              image.height, "x", image.channels, ", attenuation is ",
                              reference.width, "x", reference.height, "x", reference.channels);
    }
}

void check_intervals(const Image& attenuation, const char* what) {
    if (attenuation.channels < 1 || attenuation.channels > kMaxIntervals) {
        fail<InvalidArgument>(what, ": attenuation has ", attenuation.channels,
                              " channels (intervals must be in [1, ", kMaxIntervals, "])");
    }
}

}  // namespace

std::vector<float> interval_colours(const TransferFunction& tf, const IntervalSet& intervals) {
    require_1d(tf, "interval_colours");
    const std::vector<double>& edges = intervals.edges();
    std::vector<float> colours;
    colours.reserve(3 * static_cast<std::size_t>(intervals.count()));
    for (int j = 0; j < intervals.count(); ++j) {
        const double low = edges[j], high = edges[j + 1];
        // Colour and opacity are linear between breakpoints, their product quadratic, so one
        // Simpson step per piece is exact.
        const double weight =
            integrate(tf, low, high, 1, [&](double v) { return double(tf.evaluate(v).a); });
        for (int c = 0; c < 3; ++c) {
            double value = 0.0;
            if (weight > 0.0) {
                value = integrate(tf, low, high, 1,
                                  [&](double v) {
                                      const glm::vec4 rgba = tf.evaluate(v);
                                      return double(rgba[c]) * rgba.a;
                                  }) /
                        weight;
            } else {
                const double width = high > low ? high - low : 1.0;
                value = integrate(tf, low, high, 1,
                                  [&](double v) { return double(tf.evaluate(v)[c]); }) /
                        width;
            }
            colours.push_back(static_cast<float>(std::clamp(value, 0.0, 1.0)));
        }
    }
    return colours;
}

std::vector<double> opacity_scales(const TransferFunction& stored, const TransferFunction& edited,
                                   const IntervalSet& intervals) {
    require_1d(stored, "opacity_scales (stored)");
    require_1d(edited, "opacity_scales (edited)");
    const std::vector<double>& edges = intervals.edges();
    std::vector<double> scales;
    for (int j = 0; j < intervals.count(); ++j) {
        const double before = mean_extinction(stored, edges[j], edges[j + 1]);
        const double after = mean_extinction(edited, edges[j], edges[j + 1]);
        if (before > 0.0) {
            scales.push_back(std::min(after / before, kUnrecoverableOpacityScale));
        } else {
            scales.push_back(after > 0.0 ? kUnrecoverableOpacityScale : 1.0);
        }
    }
    return scales;
}

Image recolour(const Image& attenuation, const std::vector<float>& colours, ComputeDevice& device) {
    check_intervals(attenuation, "recolour");
    const int intervals = attenuation.channels;
    if (colours.size() != 3 * static_cast<std::size_t>(intervals)) {
        fail<InvalidArgument>("recolour: ", colours.size(), " colour values for ", intervals,
                              " intervals (expected ", 3 * intervals, ", RGB per interval)");
    }
    const std::size_t pixels = attenuation.pixel_count();
    if (pixels == 0) return Image(attenuation.width, attenuation.height, 4);
    detail::DeviceImage input, output;
    input.upload(device, attenuation, "recolour: attenuation");
    output.allocate(device, attenuation.width, attenuation.height, 4);
    const cl::Buffer colour_buffer =
        detail::upload_read_only(device, colours, "recolour: interval colours");
    cl::Kernel kernel = device.opencl().kernel("transfer_function_edit", "recolour");
    device.opencl().launch(kernel, cl::NDRange(pixels), cl::NullRange, input.buffer(),
                           static_cast<cl_int>(intervals), static_cast<cl_uint>(pixels),
                           colour_buffer, output.buffer());
    return output.download(device, "recolour: colour");
}

double optical_depth_weight(double scale) {
    if (!(scale > 0.0)) return 1.0;
    return std::clamp(-std::log2(scale) - 1.0, 0.0, 1.0);
}

Image estimate_attenuation(const Image& attenuation, const Image& mean_depth,
                           const Image* optical_depth, const std::vector<double>& scales,
                           ComputeDevice& device) {
    check_intervals(attenuation, "estimate_attenuation");
    const int intervals = attenuation.channels;
    check_same_size(mean_depth, attenuation, "mean depth");
    if (optical_depth) check_same_size(*optical_depth, attenuation, "optical depth");
    if (scales.size() != static_cast<std::size_t>(intervals)) {
        fail<InvalidArgument>("estimate_attenuation: ", scales.size(), " scales for ", intervals,
                              " intervals");
    }
    std::vector<float> scale_values;
    for (std::size_t j = 0; j < scales.size(); ++j) {
        if (!(scales[j] >= 0.0) || !std::isfinite(scales[j])) {
            fail<InvalidArgument>("estimate_attenuation: scales[", j, "] = ", scales[j],
                                  " (must be finite and >= 0)");
        }
        scale_values.push_back(static_cast<float>(scales[j]));
    }
    const std::size_t pixels = attenuation.pixel_count();
    if (pixels == 0) return Image(attenuation.width, attenuation.height, intervals);

    detail::DeviceImage a, depth, tau, output;
    a.upload(device, attenuation, "estimate_attenuation: attenuation");
    depth.upload(device, mean_depth, "estimate_attenuation: mean depth");
    if (optical_depth) tau.upload(device, *optical_depth, "estimate_attenuation: optical depth");
    output.allocate(device, attenuation.width, attenuation.height, intervals);
    const cl::Buffer scale_buffer =
        detail::upload_read_only(device, scale_values, "estimate_attenuation: scales");
    cl::Kernel kernel = device.opencl().kernel("transfer_function_edit", "estimate_attenuation");
    device.opencl().launch(kernel, cl::NDRange(pixels), cl::NullRange, a.buffer(), depth.buffer(),
                           optical_depth ? tau.buffer() : cl::Buffer(),
                           static_cast<cl_int>(optical_depth ? 1 : 0),
                           static_cast<cl_int>(intervals), static_cast<cl_uint>(pixels),
                           scale_buffer, output.buffer());
    return output.download(device, "estimate_attenuation: edited attenuation");
}

std::vector<float> interval_colour_spread(const TransferFunction& tf,
                                          const IntervalSet& intervals) {
    require_1d(tf, "interval_colour_spread");
    const std::vector<float> colours = interval_colours(tf, intervals);
    const std::vector<double>& edges = intervals.edges();
    std::vector<float> spread;
    spread.reserve(static_cast<std::size_t>(intervals.count()));
    for (int j = 0; j < intervals.count(); ++j) {
        const std::vector<double> points = breakpoints(tf, edges[j], edges[j + 1]);
        // Where the opacity is 0 on a whole piece its colour never reaches a pixel; a piece with
        // some opacity counts both of its ends (linear pieces: the extremes are at the ends).
        float worst = 0.0f;
        auto consider = [&](double value) {
            const glm::vec4 rgba = tf.evaluate(value);
            for (int c = 0; c < 3; ++c) {
                worst = std::max(worst, std::abs(rgba[c] - colours[3 * j + c]));
            }
        };
        for (std::size_t p = 0; p + 1 < points.size(); ++p) {
            const bool visible = tf.evaluate(points[p]).a > 0.0f ||
                                 tf.evaluate(points[p + 1]).a > 0.0f ||
                                 tf.evaluate(0.5 * (points[p] + points[p + 1])).a > 0.0f;
            if (!visible) continue;
            consider(points[p]);
            consider(points[p + 1]);
        }
        spread.push_back(worst);
    }
    return spread;
}

namespace {

void check_trust_image(const Image* image, const Image& reference, int channels, const char* what) {
    if (!image) return;
    if (image->width != reference.width || image->height != reference.height ||
        image->channels != channels || image->pixels.size() != reference.pixel_count() * channels) {
        fail<InvalidArgument>("edit_error: ", what, " is ", image->width, "x", image->height, "x",
                              image->channels, ", expected ", reference.width, "x",
                              reference.height, "x", channels);
    }
}

/// Interval j's transmittance t_j inferred from the walk (estimate_attenuation's definition,
/// step 2), T the transmittance inferred in front of it.
double inferred_transmittance(double a_j, double transmittance) {
    if (!(transmittance > 0.0)) return 1.0;
    const double behind = transmittance - a_j;
    return behind > kFloatAttenuationResolution ? std::clamp(behind / transmittance, 0.0, 1.0)
                                                : 0.0;
}

/// max over RGB of |x - y|.
double largest_difference(const double* x, const double* y) {
    return std::max({std::abs(x[0] - y[0]), std::abs(x[1] - y[1]), std::abs(x[2] - y[2])});
}

/// Where t_j comes from in a recomposition: the estimator's rule (optical_depth_weight), a_j
/// alone, or the edit trust's thinning alternative (tau_j's t_j by the thinning weight).
enum class TransmittanceFrom { estimator, attenuation, thinning };

/// The thinning weight of the edit trust (edit_error): 0 at s >= 1, 1 at s <= 1/2.
double thinning_weight(double scale) {
    return scale > 0.0 ? std::clamp(-std::log2(scale), 0.0, 1.0) : 1.0;
}

/// t_j taking a share w from tau_j's transmittance and the rest from the inferred one.
double blended_transmittance(double inferred, double tau_j, double w) {
    return (1.0 - w) * inferred + w * std::exp(-std::max(0.0, tau_j));
}

/// estimate_attenuation's walk over the intervals in the order [first, last) of (depth, index)
/// pairs, recomposed with `colours` into rgb: the edit's colour if the ray met the intervals
/// in that order, one run each. `tau` may be null (then t_j always comes from a_j).
template <typename Iterator>
void recompose_in_order(const float* a, const float* tau, TransmittanceFrom from,
                        const std::vector<double>& scales, const std::vector<float>& colours,
                        Iterator first, Iterator last, double* rgb) {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    double inferred_in_front = 1.0, edited_transmittance = 1.0;
    for (Iterator entry = first; entry != last; ++entry) {
        const int j = entry->second;
        const double inferred = inferred_transmittance(a[j], inferred_in_front);
        double t = inferred;
        if (tau && from != TransmittanceFrom::attenuation) {
            const double w = from == TransmittanceFrom::thinning ? thinning_weight(scales[j])
                                                                 : optical_depth_weight(scales[j]);
            t = blended_transmittance(inferred, tau[j], w);
        }
        const double edited = scales[j] > 0.0 ? std::pow(t, scales[j]) : 1.0;
        const double a_edited = edited_transmittance * (1.0 - edited);
        for (int c = 0; c < 3; ++c) rgb[c] += a_edited * colours[3 * j + c];
        inferred_in_front *= inferred;
        edited_transmittance *= edited;
    }
}

/// The scales edit_error weighs (all 1 where none are given), after checking every input's size
/// against the stored attenuation.
std::vector<double> checked_trust_scales(const EditTrustInputs& inputs) {
    if (!inputs.attenuation || !inputs.mean_depth) {
        fail<InvalidArgument>("edit_error: attenuation and mean depth are required");
    }
    const Image& stored = *inputs.attenuation;
    check_intervals(stored, "edit_error");
    const int intervals = stored.channels;
    const auto L = static_cast<std::size_t>(intervals);
    check_trust_image(inputs.mean_depth, stored, intervals, "mean depth");
    check_trust_image(inputs.optical_depth, stored, intervals, "optical depth");
    check_trust_image(inputs.edited_attenuation, stored, intervals, "edited attenuation");
    check_trust_image(inputs.interleaving, stored, 2, "interleaving");
    check_trust_image(inputs.entry_depth, stored, intervals, "entry depth");
    check_trust_image(inputs.stored_rendering, stored, 4, "stored rendering");
    const bool calibrated = inputs.stored_rendering && !inputs.colour_spread.empty();
    if (calibrated &&
        (inputs.stored_colours.size() != 3 * L || inputs.stored_colour_spread.size() != L)) {
        fail<InvalidArgument>("edit_error: ", inputs.stored_colours.size(),
                              " stored colour values and ", inputs.stored_colour_spread.size(),
                              " stored spreads for ", intervals, " intervals (expected ",
                              3 * intervals, " and ", intervals, ")");
    }
    std::vector<double> scales =
        inputs.scales.empty() ? std::vector<double>(L, 1.0) : inputs.scales;
    if (scales.size() != L || inputs.colours.size() != 3 * L ||
        (!inputs.colour_spread.empty() && inputs.colour_spread.size() != L)) {
        fail<InvalidArgument>("edit_error: ", scales.size(), " scales, ", inputs.colours.size(),
                              " colour values and ", inputs.colour_spread.size(), " spreads for ",
                              intervals, " intervals (expected ", intervals, ", ", 3 * intervals,
                              " and ", intervals, ")");
    }
    return scales;
}

/// One pixel as edit_error reads it: the stored and edited a_j, tau_j (null without optical
/// depth), and the intervals with light front to back by mean depth, as estimate_attenuation
/// walks them (ties by index).
struct TrustPixel {
    std::size_t index = 0;
    const float* a = nullptr;
    const float* a_edited = nullptr;
    const float* tau = nullptr;
    std::vector<std::pair<float, int>> order;
};

/// The precision term: how far the edit can move with each t_j known only to the resolution.
double precision_term(const TrustPixel& pixel, const std::vector<double>& scales,
                      double resolution) {
    const float* a = pixel.a;
    const float* tau = pixel.tau;
    double total = 0.0;
    double transmittance = 1.0, edited_transmittance = 1.0;
    for (const auto& [depth, j] : pixel.order) {
        (void)depth;
        const double s = scales[j];
        // t_j as the estimator takes it. Stored tau is known relatively, a_j absolutely (so
        // its t_j to within res / T); a blend of the two, as uncertain as its parts.
        const double inferred = inferred_transmittance(a[j], transmittance);
        const double w = tau ? optical_depth_weight(s) : 0.0;
        const double t = tau ? blended_transmittance(inferred, tau[j], w) : inferred;
        double uncertainty = 0.0;
        if (w > 0.0) {
            const double tau_j = std::max(0.0, double(tau[j]));
            uncertainty += w * std::exp(-tau_j) * tau_j * resolution;
        }
        if (w < 1.0 && transmittance > 0.0) uncertainty += (1.0 - w) * resolution / transmittance;
        if (s > 0.0 && uncertainty > 0.0) {
            const double high = std::min(1.0, t + uncertainty);
            total += edited_transmittance * std::abs(std::pow(high, s) - std::pow(t, s));
        }
        transmittance *= inferred;
        edited_transmittance *= s > 0.0 ? std::pow(t, s) : 1.0;
    }
    return total;
}

/// The recolouring term: the bound of what the colour inside each interval adds, calibrated
/// where the stored rendering shows what recolouring missed at the stored function.
double recolouring_term(const TrustPixel& pixel, const EditTrustInputs& inputs) {
    const std::size_t L = inputs.colour_spread.size();
    double bound = 0.0;
    for (std::size_t j = 0; j < L; ++j) bound += pixel.a_edited[j] * inputs.colour_spread[j];
    if (inputs.stored_rendering) {
        double stored_bound = 0.0, missed = 0.0;
        double rgb[3] = {0.0, 0.0, 0.0};
        for (std::size_t j = 0; j < L; ++j) {
            stored_bound += pixel.a[j] * inputs.stored_colour_spread[j];
            for (int c = 0; c < 3; ++c) rgb[c] += pixel.a[j] * inputs.stored_colours[3 * j + c];
        }
        const float* rendering = &inputs.stored_rendering->pixels[4 * pixel.index];
        for (int c = 0; c < 3; ++c) missed = std::max(missed, std::abs(rgb[c] - rendering[c]));
        if (stored_bound > kCalibratedSpreadFloor) {
            bound = std::min(bound, missed * bound / stored_bound);
        }
    }
    return bound;
}

/// The order terms (interleaving, and with the entry depth thickening's and thinning's
/// alternatives), each added to `total` in turn. `thickening` and `thinning` are the per-interval
/// weights of edit_error's definition.
class OrderTerms {
public:
    OrderTerms(const EditTrustInputs& inputs, const std::vector<double>& scales)
        : inputs_(inputs), scales_(scales), thickening_(scales.size()), thinning_(scales.size()) {
        for (std::size_t j = 0; j < scales.size(); ++j) {
            const double octaves = scales[j] > 0.0 ? std::log2(scales[j]) : -INFINITY;
            thickening_[j] = std::clamp(octaves / 2.0, 0.0, 1.0);
            thinning_[j] = thinning_weight(scales[j]);
        }
        entry_order_.reserve(scales.size());
    }

    void add(const TrustPixel& pixel, double& total) {
        double light = 0.0, thick = 0.0, thin = 0.0;
        for (std::size_t j = 0; j < scales_.size(); ++j) {
            light += pixel.a[j];
            thick += pixel.a[j] * thickening_[j];
            thin += pixel.a[j] * thinning_[j];
        }
        if (!inputs_.entry_depth) {
            total += interleaving(pixel, light);
        } else if (pixel.order.size() > 1 && light > 0.0) {
            // Order: the shown estimate against the entry-depth order (thickening); thinning's
            // two estimates against each other with tau, else the interleaving term for the
            // thinned share of the light.
            if (thick > 0.0) total += thick / light * entry_order_difference(pixel);
            if (pixel.tau && thin > 0.0) {
                // The two estimates of thinning disagree by this much; the estimator takes one
                // or the other (or between) by s_j, and either may be the wrong one.
                double from_attenuation[3], from_thinning[3];
                recompose(pixel, TransmittanceFrom::attenuation, pixel.order, from_attenuation);
                recompose(pixel, TransmittanceFrom::thinning, pixel.order, from_thinning);
                total += largest_difference(from_thinning, from_attenuation);
            } else if (thin > 0.0) {
                total += thin / light * interleaving(pixel, light);
            }
        }
    }

private:
    void recompose(const TrustPixel& pixel, TransmittanceFrom from,
                   const std::vector<std::pair<float, int>>& order, double* rgb) const {
        recompose_in_order(pixel.a, pixel.tau, from, scales_, inputs_.colours, order.begin(),
                           order.end(), rgb);
    }

    // Interleaving: where the ray re-entered intervals, the one-run-per-interval order the
    // estimator assumed holds only for the light of first runs. The estimate in the reverse
    // order (nearest last) is the other extreme; the light of the re-entered runs, as a share of
    // the pixel's, says how far towards it the truth may lie. 0 without an opacity edit: both
    // orders then return a itself.
    double interleaving(const TrustPixel& pixel, double light) const {
        const float* counts =
            inputs_.interleaving ? &inputs_.interleaving->pixels[2 * pixel.index] : nullptr;
        if (!counts || !(counts[0] > 0.0f) || pixel.order.size() < 2) return 0.0;
        const double share = light > 0.0 ? std::min(1.0, counts[1] / light) : 0.0;
        double forward[3], backward[3];
        recompose(pixel, TransmittanceFrom::estimator, pixel.order, forward);
        recompose_in_order(pixel.a, pixel.tau, TransmittanceFrom::estimator, scales_,
                           inputs_.colours, pixel.order.rbegin(), pixel.order.rend(), backward);
        return share * largest_difference(forward, backward);
    }

    /// The shown estimate against the one recomposed from a_j in entry-depth order.
    double entry_order_difference(const TrustPixel& pixel) {
        double shown[3], other[3];
        recompose(pixel, TransmittanceFrom::estimator, pixel.order, shown);
        const float* entry = &inputs_.entry_depth->pixels[pixel.index * scales_.size()];
        entry_order_.clear();
        for (const auto& [depth, j] : pixel.order) {
            (void)depth;
            entry_order_.emplace_back(std::isnan(entry[j]) ? INFINITY : entry[j], j);
        }
        std::stable_sort(entry_order_.begin(), entry_order_.end(),
                         [](const auto& x, const auto& y) { return x.first < y.first; });
        recompose(pixel, TransmittanceFrom::attenuation, entry_order_, other);
        return largest_difference(other, shown);
    }

    const EditTrustInputs& inputs_;
    const std::vector<double>& scales_;
    std::vector<double> thickening_, thinning_;
    std::vector<std::pair<float, int>> entry_order_;
};

}  // namespace

Image edit_error(const EditTrustInputs& inputs) {
    const std::vector<double> scales = checked_trust_scales(inputs);
    const Image& stored = *inputs.attenuation;
    const auto L = static_cast<std::size_t>(stored.channels);
    const bool unrecoverable = std::any_of(
        scales.begin(), scales.end(), [](double s) { return s >= kUnrecoverableOpacityScale; });
    const Image& edited = inputs.edited_attenuation ? *inputs.edited_attenuation : stored;

    Image error(stored.width, stored.height, 1);
    if (unrecoverable) {
        std::fill(error.pixels.begin(), error.pixels.end(), 1.0f);
        return error;
    }
    OrderTerms order_terms(inputs, scales);
    TrustPixel pixel;
    pixel.order.reserve(L);
    for (std::size_t p = 0; p < stored.pixel_count(); ++p) {
        pixel.index = p;
        pixel.a = &stored.pixels[p * L];
        pixel.a_edited = &edited.pixels[p * L];
        pixel.tau = inputs.optical_depth ? &inputs.optical_depth->pixels[p * L] : nullptr;
        const float* z = &inputs.mean_depth->pixels[p * L];
        pixel.order.clear();
        for (std::size_t j = 0; j < L; ++j) {
            if (pixel.a[j] > 0.0f)
                pixel.order.emplace_back(std::isnan(z[j]) ? INFINITY : z[j], int(j));
        }
        std::stable_sort(pixel.order.begin(), pixel.order.end(),
                         [](const auto& x, const auto& y) { return x.first < y.first; });

        double total = precision_term(pixel, scales, inputs.attenuation_resolution);
        if (!inputs.colour_spread.empty()) total += recolouring_term(pixel, inputs);
        order_terms.add(pixel, total);
        error.pixels[p] = static_cast<float>(total);
    }
    return error;
}

void add_model_departure(Image& error, const Image& predicted, const Image& recomposed) {
    if (predicted.pixel_count() != error.pixel_count() ||
        recomposed.pixel_count() != error.pixel_count() || predicted.channels < 3 ||
        recomposed.channels < 3 || error.channels != 1) {
        fail<InvalidArgument>("add_model_departure: images of ", predicted.pixel_count(), ", ",
                              recomposed.pixel_count(), " and ", error.pixel_count(),
                              " pixels (expected one size, RGB(A) and 1 channel)");
    }
    for (std::size_t p = 0; p < error.pixel_count(); ++p) {
        float worst = 0.0f;
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(predicted.pixels[p * predicted.channels + c] -
                                             recomposed.pixels[p * recomposed.channels + c]));
        }
        error.pixels[p] += worst;
    }
}

Image edit_confidence(const Image& error) {
    Image confidence(error.width, error.height, 1);
    for (std::size_t p = 0; p < error.pixel_count(); ++p) {
        const double e = error.pixels[p * error.channels];
        confidence.pixels[p] = static_cast<float>(
            std::isnan(e) ? 0.0 : std::clamp(1.0 - e / (2.0 * kEditErrorTolerance), 0.0, 1.0));
    }
    return confidence;
}

}  // namespace insitu
