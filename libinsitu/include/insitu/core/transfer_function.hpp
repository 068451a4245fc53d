#pragma once
// Transfer functions: value -> (r, g, b, opacity), piecewise-linear between control points sorted
// by value and clamped outside (DESIGN.md). Opacity `a` is per `unit_length` world units;
// renderers correct it for their step: alpha_step = 1 - (1 - a)^(step / unit_length).
//
// A 2D function (value x gradient magnitude, seed 002) is a list of 1D rows, each at a gradient
// magnitude (field units per world unit); between rows it interpolates linearly, outside them it
// clamps. JSON:
//   1D: {"points": [[value, r, g, b, a], ...], "unit_length": 1.0}
//   2D: {"gradient_rows": [{"gradient_magnitude": 0.0, "points": [...]}, ...], "unit_length": 1.0}
#include <glm/vec4.hpp>
#include <iosfwd>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace insitu {

struct ControlPoint {
    double value = 0.0;
    glm::vec4 rgba{0.0f};  ///< colour in [0, 1], opacity in [0, 1] per unit_length
};

/// One 1D function over values at a given gradient magnitude.
struct TransferRow {
    double gradient_magnitude = 0.0;
    std::vector<ControlPoint> points;
};

/// A transfer function sampled into a table for a device: `value_bins` x `gradient_bins` RGBA,
/// value axis fastest, spanning [value_min, value_max] x [0, gradient_max].
struct TransferTable {
    int value_bins = 0;
    int gradient_bins = 1;
    double value_min = 0.0;
    double value_max = 1.0;
    double gradient_max = 0.0;
    std::vector<float> rgba;  ///< value_bins * gradient_bins * 4
};

class TransferFunction {
public:
    /// A 1D function; throws InvalidArgument for no points, unsorted or non-finite values,
    /// components outside [0, 1] or a non-positive unit length.
    TransferFunction(std::vector<ControlPoint> points, double unit_length = 1.0);
    /// A 2D function; rows sorted by strictly increasing gradient magnitude >= 0.
    TransferFunction(std::vector<TransferRow> rows, double unit_length);

    static TransferFunction from_json(const nlohmann::json& json);
    /// Parses text; ParseError names the position, InvalidArgument the offending value.
    static TransferFunction from_json_text(const std::string& text);
    static TransferFunction from_json_file(const std::string& path);
    nlohmann::json to_json() const;

    bool is_2d() const { return rows_.size() > 1; }
    double unit_length() const { return unit_length_; }
    const std::vector<TransferRow>& rows() const { return rows_; }
    /// Smallest and largest control-point value over all rows.
    double value_min() const;
    double value_max() const;

    /// The exact piecewise-(bi)linear function; gradient ignored for 1D functions.
    glm::vec4 evaluate(double value, double gradient_magnitude = 0.0) const;

    /// Samples into a table; `value_bins` >= 2 and, for 2D, `gradient_bins` >= 2.
    TransferTable sample(int value_bins = 1024, int gradient_bins = 64) const;

private:
    std::vector<TransferRow> rows_;
    double unit_length_ = 1.0;
};

std::ostream& operator<<(std::ostream& out, const TransferFunction& tf);

}  // namespace insitu
