// Transfer-function edits from attenuation proxies (seed 000 §6): host side of
// kernels/explore/transfer_function_edit.cl, and the per-interval summaries of transfer functions.
#include "insitu/explore/transfer_function_edit.hpp"

#include <algorithm>
#include <cmath>

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

}  // namespace insitu
