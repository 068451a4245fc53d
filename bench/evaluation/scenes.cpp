#include "scenes.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "gray_scott_simulation.hpp"
#include "gray_scott_volume.hpp"
#include "insitu/error.hpp"

namespace insitu::evaluation {

Scene make_scene(std::string name, SampledVolume volume) {
    Scene scene;
    scene.name = std::move(name);
    scene.volume = std::move(volume);
    const ValueRange range = scene.volume.field().value_range();
    if (range.empty() || !(range.max > range.min)) {
        fail<InvalidArgument>("scene \"", scene.name, "\": value range ", range,
                              " (needs finite samples that are not all equal)");
    }
    scene.value_min = range.min;
    scene.value_max = range.max;
    const Bounds bounds = scene.volume.field().bounds();
    const glm::dvec3 extent = bounds.upper - bounds.lower;
    scene.unit_length = std::max({extent.x, extent.y, extent.z}) / 64.0;
    return scene;
}

std::vector<Scene> gray_scott_scenes(int size, const std::vector<int>& snapshot_steps) {
    gray_scott::Parameters parameters;
    parameters.size = size;
    gray_scott::Simulation simulation(parameters);
    std::vector<Scene> scenes;
    for (const int snapshot : snapshot_steps) {
        while (simulation.steps_done() < snapshot) simulation.step();
        SampledVolume volume = bench::gray_scott_volume(simulation);
        scenes.push_back(make_scene("gray_scott_t" + std::to_string(snapshot), std::move(volume)));
    }
    return scenes;
}

namespace {

template <typename T>
void convert(const std::vector<char>& bytes, std::vector<float>& out) {
    for (std::size_t i = 0; i < out.size(); ++i) {
        T value;
        std::memcpy(&value, bytes.data() + i * sizeof(T), sizeof(T));
        out[i] = static_cast<float>(value);
    }
}

}  // namespace

Scene load_raw(const std::string& path, Index3 dims, ScalarType type) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<IoError>("raw field \"", path, "\": cannot open");
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    const std::size_t samples = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    if (bytes.size() != samples * scalar_size_bytes(type)) {
        fail<IoError>("raw field \"", path, "\": ", bytes.size(), " bytes, expected ", dims[0], "x",
                      dims[1], "x", dims[2], " ", to_string(type), " = ",
                      samples * scalar_size_bytes(type));
    }
    SampledVolume volume;
    volume.name = "raw";
    volume.dims = dims;
    volume.values.resize(samples);
    switch (type) {
        case ScalarType::uint8:
            convert<std::uint8_t>(bytes, volume.values);
            break;
        case ScalarType::uint16:
            convert<std::uint16_t>(bytes, volume.values);
            break;
        case ScalarType::int16:
            convert<std::int16_t>(bytes, volume.values);
            break;
        case ScalarType::float32:
            convert<float>(bytes, volume.values);
            break;
        case ScalarType::float64:
            convert<double>(bytes, volume.values);
            break;
    }
    std::string name = path.substr(path.find_last_of('/') + 1);
    return make_scene("raw_" + name, std::move(volume));
}

namespace {

glm::vec3 lerp_colours(const std::vector<glm::vec3>& stops, double x) {
    const double position = std::clamp(x, 0.0, 1.0) * (stops.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(position), stops.size() - 2);
    const float f = static_cast<float>(position - i);
    return stops[i] * (1.0f - f) + stops[i + 1] * f;
}

const std::vector<glm::vec3> kRamp{
    {0.1f, 0.2f, 0.9f}, {0.1f, 0.8f, 0.9f}, {0.9f, 0.9f, 0.2f}, {0.9f, 0.2f, 0.1f}};
const std::vector<glm::vec3> kOther{{0.5f, 0.1f, 0.6f}, {0.2f, 0.7f, 0.3f}, {1.0f, 0.6f, 0.1f}};

/// Opacity per unit length of the stored function at normalised value x.
double base_opacity(double x) {
    const double ramp = std::clamp((x - 0.15) / 0.85, 0.0, 1.0);
    return 0.6 * std::pow(ramp, 1.5);
}

}  // namespace

TransferFunction make_tf(const Scene& scene, const TfSpec& spec) {
    const double lo = scene.value_min, width = scene.value_max - scene.value_min;
    // The piecewise colours are constant over interval j except within kEdge of its edges.
    constexpr double kEdge = 1e-6;
    auto colour_at = [&](double x) -> glm::vec3 {
        switch (spec.colours) {
            case TfSpec::Colours::ramp:
                return lerp_colours(kRamp, x);
            case TfSpec::Colours::other:
                return lerp_colours(kOther, x);
            case TfSpec::Colours::piecewise: {
                const int j = std::clamp(static_cast<int>(std::floor(x * spec.intervals)), 0,
                                         spec.intervals - 1);
                return lerp_colours(kOther, (j + 0.5) / spec.intervals);
            }
        }
        return glm::vec3(0.0f);
    };
    auto opacity_at = [&](double x, bool low_band) {
        return std::min(
            1.0, base_opacity(x) * spec.scale * (low_band ? spec.low_scale : spec.high_scale));
    };
    std::vector<double> xs;
    for (int j = 0; j <= 16; ++j) xs.push_back(j / 16.0);
    if (spec.colours == TfSpec::Colours::piecewise) {
        for (int j = 0; j <= spec.intervals; ++j) {
            const double edge = static_cast<double>(j) / spec.intervals;
            if (j > 0) xs.push_back(edge - kEdge);
            if (j < spec.intervals) xs.push_back(edge + kEdge);
        }
    }
    xs.push_back(0.5 - kEdge);
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
    std::vector<ControlPoint> points;
    for (const double x : xs) {
        // Colour piecewise: a point exactly on an edge takes the interval above it.
        const glm::vec3 rgb = colour_at(spec.colours == TfSpec::Colours::piecewise
                                            ? std::min(x + 0.5 * kEdge, 1.0 - kEdge)
                                            : x);
        const float a = static_cast<float>(opacity_at(x, x < 0.5));
        points.push_back({lo + width * x, glm::vec4(rgb, a)});
    }
    return TransferFunction(points, scene.unit_length);
}

TransferFunction make_sharp_tf(const Scene& scene, int peaks, double width) {
    const double lo = scene.value_min, range = scene.value_max - scene.value_min;
    const std::vector<glm::vec3> colours{
        {0.2f, 0.4f, 1.0f}, {0.2f, 1.0f, 0.3f}, {1.0f, 0.3f, 0.1f}, {1.0f, 0.9f, 0.2f}};
    std::vector<ControlPoint> points{{lo, glm::vec4(colours[0], 0.0f)}};
    for (int p = 0; p < peaks; ++p) {
        const double centre = peaks == 1 ? 0.5 : 0.3 + 0.4 * p / (peaks - 1);
        const glm::vec3 rgb = colours[static_cast<std::size_t>(p) % colours.size()];
        points.push_back({lo + range * (centre - 0.5 * width), glm::vec4(rgb, 0.0f)});
        points.push_back({lo + range * centre, glm::vec4(rgb, 0.8f)});
        points.push_back({lo + range * (centre + 0.5 * width), glm::vec4(rgb, 0.0f)});
    }
    points.push_back({scene.value_max, glm::vec4(colours[0], 0.0f)});
    return TransferFunction(points, scene.unit_length);
}

IntervalSet scene_intervals(const Scene& scene, int count) {
    return IntervalSet::uniform(scene.value_min, scene.value_max, count);
}

std::vector<double> scene_layers(const Scene& scene, int count) {
    std::vector<double> isovalues;
    for (int l = 0; l < count; ++l) {
        const double x = count == 1 ? 0.3 : 0.3 + 0.45 * l / (count - 1);
        isovalues.push_back(scene.value_min + x * (scene.value_max - scene.value_min));
    }
    return isovalues;
}

std::vector<TfSpec> held_out_edits(int count) {
    std::vector<TfSpec> edits;
    for (int i = 1; i <= count; ++i) {
        const double t = static_cast<double>(i) / count;
        TfSpec spec;
        spec.low_scale = 1.0 - 0.75 * t;
        spec.high_scale = 1.0 - 0.4 * t;
        edits.push_back(spec);
    }
    return edits;
}

std::vector<TfSpec> training_specs(int count) {
    // (low, high) = (1, 1), (0.2, 1), (0.2, 0.3): every held-out edit (1 - 0.75 t, 1 - 0.4 t)
    // lies inside the triangle they span.
    std::vector<TfSpec> specs(1);
    if (count >= 2) specs.push_back(TfSpec{0.2, 1.0});
    if (count >= 3) specs.push_back(TfSpec{0.2, 0.3});
    return specs;
}

}  // namespace insitu::evaluation
