#include "insitu/core/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "insitu/error.hpp"

namespace insitu {

namespace {

void validate_row(const TransferRow& row, const std::string& where) {
    if (row.points.empty()) fail<InvalidArgument>(where, ": no control points");
    for (std::size_t i = 0; i < row.points.size(); ++i) {
        const ControlPoint& point = row.points[i];
        if (!std::isfinite(point.value)) {
            fail<InvalidArgument>(where, ": points[", i, "] value = ", point.value,
                                  " (must be finite)");
        }
        if (i > 0 && point.value < row.points[i - 1].value) {
            fail<InvalidArgument>(where, ": points[", i, "] value = ", point.value,
                                  " is below points[", i - 1, "] value = ", row.points[i - 1].value,
                                  " (points must be sorted by value)");
        }
        for (int c = 0; c < 4; ++c) {
            const float component = point.rgba[c];
            if (!(component >= 0.0f && component <= 1.0f)) {
                fail<InvalidArgument>(where, ": points[", i, "] ", "rgba"[c], " = ", component,
                                      " (must be in [0, 1])");
            }
        }
    }
}

void validate_unit_length(double unit_length) {
    if (!(unit_length > 0.0) || !std::isfinite(unit_length)) {
        fail<InvalidArgument>("transfer function: unit_length = ", unit_length,
                              " (must be finite and > 0)");
    }
}

// Piecewise-linear in value, clamped outside the first and last point.
glm::vec4 evaluate_row(const TransferRow& row, double value) {
    const auto& points = row.points;
    if (!(value > points.front().value)) return points.front().rgba;
    if (!(value < points.back().value)) return points.back().rgba;
    const auto upper =
        std::upper_bound(points.begin(), points.end(), value,
                         [](double v, const ControlPoint& p) { return v < p.value; });
    const ControlPoint& right = *upper;
    const ControlPoint& left = *(upper - 1);
    const double span = right.value - left.value;
    const float t = span > 0.0 ? static_cast<float>((value - left.value) / span) : 1.0f;
    return left.rgba + t * (right.rgba - left.rgba);
}

std::vector<ControlPoint> points_from_json(const nlohmann::json& json, const std::string& where) {
    if (!json.is_array()) fail<ParseError>(where, ": \"points\" must be an array");
    std::vector<ControlPoint> points;
    for (std::size_t i = 0; i < json.size(); ++i) {
        const auto& entry = json[i];
        if (!entry.is_array() || entry.size() != 5) {
            fail<ParseError>(where, ": points[", i, "] = ", entry.dump(),
                             " (expected [value, r, g, b, a])");
        }
        for (std::size_t c = 0; c < 5; ++c) {
            if (!entry[c].is_number()) {
                fail<ParseError>(where, ": points[", i, "][", c, "] = ", entry[c].dump(),
                                 " (expected a number)");
            }
        }
        points.push_back(
            {entry[0].get<double>(), glm::vec4(entry[1].get<float>(), entry[2].get<float>(),
                                               entry[3].get<float>(), entry[4].get<float>())});
    }
    return points;
}

nlohmann::json points_to_json(const std::vector<ControlPoint>& points) {
    nlohmann::json array = nlohmann::json::array();
    for (const ControlPoint& p : points) {
        array.push_back({p.value, p.rgba.r, p.rgba.g, p.rgba.b, p.rgba.a});
    }
    return array;
}

}  // namespace

TransferFunction::TransferFunction(std::vector<ControlPoint> points, double unit_length)
    : rows_{TransferRow{0.0, std::move(points)}}, unit_length_(unit_length) {
    validate_row(rows_.front(), "transfer function");
    validate_unit_length(unit_length_);
}

TransferFunction::TransferFunction(std::vector<TransferRow> rows, double unit_length)
    : rows_(std::move(rows)), unit_length_(unit_length) {
    if (rows_.empty()) fail<InvalidArgument>("transfer function: no gradient rows");
    for (std::size_t r = 0; r < rows_.size(); ++r) {
        const std::string where = "transfer function gradient_rows[" + std::to_string(r) + "]";
        const double g = rows_[r].gradient_magnitude;
        if (!(g >= 0.0) || !std::isfinite(g)) {
            fail<InvalidArgument>(where, ": gradient_magnitude = ", g, " (must be finite, >= 0)");
        }
        if (r > 0 && !(g > rows_[r - 1].gradient_magnitude)) {
            fail<InvalidArgument>(where, ": gradient_magnitude = ", g,
                                  " (rows must have strictly increasing gradient magnitudes)");
        }
        validate_row(rows_[r], where);
    }
    validate_unit_length(unit_length_);
}

TransferFunction TransferFunction::from_json(const nlohmann::json& json) {
    if (!json.is_object()) fail<ParseError>("transfer function: expected a JSON object");
    for (const auto& item : json.items()) {
        if (item.key() != "points" && item.key() != "gradient_rows" &&
            item.key() != "unit_length") {
            fail<ParseError>("transfer function: unknown key \"", item.key(),
                             "\" (expected points, gradient_rows, unit_length)");
        }
    }
    double unit_length = 1.0;
    if (json.contains("unit_length")) {
        if (!json["unit_length"].is_number()) {
            fail<ParseError>("transfer function: unit_length = ", json["unit_length"].dump(),
                             " (expected a number)");
        }
        unit_length = json["unit_length"].get<double>();
    }
    const bool has_points = json.contains("points");
    const bool has_rows = json.contains("gradient_rows");
    if (has_points == has_rows) {
        fail<ParseError>(
            "transfer function: give exactly one of \"points\" (1D) or "
            "\"gradient_rows\" (2D)");
    }
    if (has_points) {
        return TransferFunction(points_from_json(json["points"], "transfer function"), unit_length);
    }
    const auto& rows_json = json["gradient_rows"];
    if (!rows_json.is_array())
        fail<ParseError>("transfer function: gradient_rows must be an array");
    std::vector<TransferRow> rows;
    for (std::size_t r = 0; r < rows_json.size(); ++r) {
        const std::string where = "transfer function gradient_rows[" + std::to_string(r) + "]";
        const auto& row = rows_json[r];
        if (!row.is_object() || !row.contains("gradient_magnitude") || !row.contains("points") ||
            !row["gradient_magnitude"].is_number()) {
            fail<ParseError>(where, " = ", row.dump(),
                             " (expected {\"gradient_magnitude\": number, \"points\": [...]})");
        }
        rows.push_back(
            {row["gradient_magnitude"].get<double>(), points_from_json(row["points"], where)});
    }
    return TransferFunction(std::move(rows), unit_length);
}

TransferFunction TransferFunction::from_json_text(const std::string& text) {
    nlohmann::json json;
    try {
        json = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& error) {
        fail<ParseError>("transfer function: malformed JSON at byte ", error.byte, ": ",
                         error.what());
    }
    return from_json(json);
}

TransferFunction TransferFunction::from_json_file(const std::string& path) {
    // An ifstream opens a directory and then reads nothing, which would read as malformed JSON.
    std::error_code ignored;
    if (std::filesystem::is_directory(path, ignored)) {
        fail<IoError>("transfer function file \"", path, "\" is a directory");
    }
    std::ifstream in(path);
    if (!in) fail<IoError>("cannot open transfer function file \"", path, "\"");
    std::stringstream buffer;
    buffer << in.rdbuf();
    try {
        return from_json_text(buffer.str());
    } catch (const ParseError& error) {
        fail<ParseError>(path, ": ", error.what());
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>(path, ": ", error.what());
    }
}

nlohmann::json TransferFunction::to_json() const {
    nlohmann::json json;
    if (is_2d()) {
        nlohmann::json rows = nlohmann::json::array();
        for (const TransferRow& row : rows_) {
            rows.push_back({{"gradient_magnitude", row.gradient_magnitude},
                            {"points", points_to_json(row.points)}});
        }
        json["gradient_rows"] = rows;
    } else {
        json["points"] = points_to_json(rows_.front().points);
    }
    json["unit_length"] = unit_length_;
    return json;
}

double TransferFunction::value_min() const {
    double result = rows_.front().points.front().value;
    for (const auto& row : rows_) result = std::min(result, row.points.front().value);
    return result;
}

double TransferFunction::value_max() const {
    double result = rows_.front().points.back().value;
    for (const auto& row : rows_) result = std::max(result, row.points.back().value);
    return result;
}

glm::vec4 TransferFunction::evaluate(double value, double gradient_magnitude) const {
    if (!is_2d() || !(gradient_magnitude > rows_.front().gradient_magnitude)) {
        return evaluate_row(rows_.front(), value);
    }
    if (!(gradient_magnitude < rows_.back().gradient_magnitude)) {
        return evaluate_row(rows_.back(), value);
    }
    std::size_t upper = 1;
    while (rows_[upper].gradient_magnitude <= gradient_magnitude) ++upper;
    const TransferRow& low = rows_[upper - 1];
    const TransferRow& high = rows_[upper];
    const float t = static_cast<float>((gradient_magnitude - low.gradient_magnitude) /
                                       (high.gradient_magnitude - low.gradient_magnitude));
    const glm::vec4 a = evaluate_row(low, value);
    return a + t * (evaluate_row(high, value) - a);
}

TransferTable TransferFunction::sample(int value_bins, int gradient_bins) const {
    if (value_bins < 2) fail<InvalidArgument>("transfer table value_bins = ", value_bins, " (< 2)");
    if (is_2d() && gradient_bins < 2) {
        fail<InvalidArgument>("transfer table gradient_bins = ", gradient_bins, " (< 2)");
    }
    TransferTable table;
    table.value_bins = value_bins;
    table.gradient_bins = is_2d() ? gradient_bins : 1;
    table.value_min = value_min();
    table.value_max = value_max();
    // A degenerate (single-value) function still gets a non-empty domain for the lookup.
    if (!(table.value_max > table.value_min)) table.value_max = table.value_min + 1.0;
    table.gradient_max = is_2d() ? rows_.back().gradient_magnitude : 0.0;
    table.rgba.resize(static_cast<std::size_t>(table.value_bins) * table.gradient_bins * 4);
    for (int g = 0; g < table.gradient_bins; ++g) {
        const double gradient =
            table.gradient_bins > 1 ? table.gradient_max * g / (table.gradient_bins - 1) : 0.0;
        for (int v = 0; v < table.value_bins; ++v) {
            const double value =
                table.value_min + (table.value_max - table.value_min) * v / (table.value_bins - 1);
            const glm::vec4 rgba = evaluate(value, gradient);
            float* out = &table.rgba[(static_cast<std::size_t>(g) * table.value_bins + v) * 4];
            for (int c = 0; c < 4; ++c) out[c] = rgba[c];
        }
    }
    return table;
}

std::ostream& operator<<(std::ostream& out, const TransferFunction& tf) {
    return out << "TransferFunction" << tf.to_json().dump();
}

}  // namespace insitu
