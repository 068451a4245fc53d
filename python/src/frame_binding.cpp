// Archive.render: a frame of any view, transfer function, lighting, occlusion and enhancement,
// as insitu-view render makes it. The keywords are spelled into the same option text the CLI
// and the web viewer parse (viewer/explore_options.hpp), so one parser builds the request and
// the frame is the CLI's, pixel for pixel; numbers go through Python's repr, which round-trips.
#include <fstream>
#include <sstream>

#include "archive.hpp"
#include "bindings.hpp"
#include "explore_options.hpp"
#include "insitu/error.hpp"

namespace insitu::python {

namespace {

std::string number_text(py::handle value, const char* key) {
    try {
        return py::repr(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
    } catch (const py::error_already_set&) {
        fail<InvalidArgument>(key, " = ", py::repr(value).cast<std::string>(), " is not a number");
    }
}

std::string numbers_text(py::handle values, const char* key) {
    std::string text;
    for (py::handle value : values) text += (text.empty() ? "" : ",") + number_text(value, key);
    return text;
}

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<IoError>("tf: cannot read \"", path, "\"");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// {J: S} or [(J, S), ...] as "J=S,J=S".
std::string scales_text(py::handle scales, const char* key) {
    py::object pairs = py::isinstance<py::dict>(scales)
                           ? py::reinterpret_borrow<py::dict>(scales).attr("items")()
                           : py::reinterpret_borrow<py::object>(scales);
    std::string text;
    for (py::handle pair : pairs) {
        const auto index = py::reinterpret_borrow<py::sequence>(pair)[0];
        const auto factor = py::reinterpret_borrow<py::sequence>(pair)[1];
        text += (text.empty() ? "" : ",") + py::str(index).cast<std::string>() + "=" +
                number_text(factor, key);
    }
    return text;
}

/// "camera" or (AZ, EL[, DIFFUSE[, SPECULAR]]) per light, joined by ';' as --light repeated.
std::string lights_text(py::handle lights) {
    std::string text;
    for (py::handle light : lights) {
        const std::string one = py::isinstance<py::str>(light) ? light.cast<std::string>()
                                                               : numbers_text(light, "lights");
        text += (text.empty() ? "" : ";") + one;
    }
    return text;
}

/// True (default radius), a radius, or (radius, strength).
std::string ao_text(py::handle ao) {
    if (py::isinstance<py::bool_>(ao)) return "on";
    if (py::isinstance<py::int_>(ao)) return py::str(ao).cast<std::string>();
    const auto parts = py::reinterpret_borrow<py::sequence>(ao);
    std::string text = py::str(parts[0]).cast<std::string>();
    if (parts.size() > 1) text += "," + number_text(parts[1], "ao");
    return text;
}

struct RenderArguments {
    std::int64_t step = 0;
    int view = 0;
    py::object azimuth, elevation, tf, opacity_scale, segment_opacity, colours, source, lights,
        ambient, ao, enhance, fill;
};

viewer::Options options_of(const RenderArguments& args) {
    viewer::Options options{{"step", std::to_string(args.step)},
                            {"view", std::to_string(args.view)}};
    const auto given = [](const py::object& value) { return !value.is_none(); };
    if (given(args.azimuth)) options["azimuth"] = number_text(args.azimuth, "azimuth");
    if (given(args.elevation)) options["elevation"] = number_text(args.elevation, "elevation");
    if (given(args.tf)) {
        options["tf"] = py::isinstance<py::dict>(args.tf)
                            ? from_python(args.tf, "tf").dump()
                            : read_text(py::str(py::module_::import("os").attr("fspath")(args.tf))
                                            .cast<std::string>());
    }
    if (given(args.opacity_scale)) {
        options["opacity-scale"] = scales_text(args.opacity_scale, "opacity_scale");
    }
    if (given(args.segment_opacity)) {
        options["segment-opacity"] = scales_text(args.segment_opacity, "segment_opacity");
    }
    if (given(args.colours)) options["colour"] = py::str(args.colours).cast<std::string>();
    if (given(args.source)) options["source"] = py::str(args.source).cast<std::string>();
    if (given(args.lights)) options["light"] = lights_text(args.lights);
    if (given(args.ambient)) options["ambient"] = number_text(args.ambient, "ambient");
    if (given(args.ao) && !(py::isinstance<py::bool_>(args.ao) && !args.ao.cast<bool>())) {
        options["ao"] = ao_text(args.ao);
    }
    if (given(args.enhance)) options["enhance"] = numbers_text(args.enhance, "enhance");
    if (given(args.fill)) options["fill"] = py::str(args.fill).cast<std::string>();
    return options;
}

py::array srgb8_of(const Image& image) {
    const std::vector<std::uint8_t> bytes = to_srgb8(image);
    std::vector<py::ssize_t> shape{image.height, image.width, image.channels};
    if (image.channels == 1) shape.pop_back();
    py::array_t<std::uint8_t> out(shape);
    std::copy(bytes.begin(), bytes.end(), out.mutable_data());
    return std::move(out);
}

/// A float32 array (height, width[, channels]) as an Image (a copy).
Image image_of(const py::array_t<float, py::array::c_style | py::array::forcecast>& array) {
    if (array.ndim() != 2 && array.ndim() != 3) {
        fail<InvalidArgument>("to_srgb8: an array of ", array.ndim(),
                              " dimensions (expected height, width[, channels])");
    }
    Image image(static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0)),
                array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1);
    std::copy(array.data(), array.data() + array.size(), image.pixels.begin());
    return image;
}

void bind_frame_class(py::module_& module) {
    py::class_<ExploreFrame, std::shared_ptr<ExploreFrame>>(
        module, "Frame",
        "One rendered frame (Archive.render): the Explorer's pixels, as insitu-view render "
        "writes them (its EXR holds rgba exactly; its PNG is srgb8()).")
        .def_property_readonly(
            "rgba",
            [](py::object self) {
                return image_view(self.cast<const ExploreFrame&>().colour, self);
            },
            "Linear, premultiplied RGBA, float32 (height, width, 4), a read-only view.")
        .def_property_readonly(
            "confidence",
            [](py::object self) {
                return image_view(self.cast<const ExploreFrame&>().confidence, self, true);
            },
            "Per pixel in [0, 1] (height, width): 1 stored or well supported, 0 a hole.")
        .def(
            "srgb8", [](const ExploreFrame& f) { return srgb8_of(f.colour); },
            "The frame as 8-bit sRGB with straight alpha (height, width, 4), uint8: the pixels "
            "of render's PNG.")
        .def_property_readonly(
            "camera", [](const ExploreFrame& f) { return to_python(f.camera.to_json()); },
            "The camera the frame was made for.")
        .def_readonly("synthesised_view", &ExploreFrame::synthesised_view,
                      "Whether the view differs from the stored one.")
        .def_property_readonly(
            "colour_source", [](const ExploreFrame& f) { return to_string(f.colour_source); },
            "What coloured it: stored, captured, model or recompose.")
        .def_property_readonly(
            "proxy_source", [](const ExploreFrame& f) { return to_string(f.proxy_source); },
            "What the pixels came from: single, multi, lightfield, volume, or auto (fused).")
        .def_readonly("opacity_scales", &ExploreFrame::opacity_scales,
                      "Per interval, the opacity scales applied (empty: none).")
        .def_readonly("light_field_share", &ExploreFrame::light_field_share,
                      "Share of pixels taken from the light field.")
        .def_readonly("missing_cameras", &ExploreFrame::missing_cameras,
                      "Light-field cameras the frame needed but the archive lacks.")
        .def_readonly("milliseconds", &ExploreFrame::milliseconds,
                      "Wall time of the Explorer's render, archive reads included.")
        .def_readonly("note", &ExploreFrame::note,
                      "What the frame could not do of the request (empty: everything).");
}

}  // namespace

void bind_frames(py::module_& module) {
    bind_frame_class(module);
    auto archive = py::reinterpret_borrow<py::class_<Archive, std::shared_ptr<Archive>>>(
        module.attr("Archive"));
    archive.def(
        "render",
        [](Archive& a, std::int64_t step, int view, py::object azimuth, py::object elevation,
           py::object tf, py::object opacity_scale, py::object segment_opacity, py::object colours,
           py::object source, py::object lights, py::object ambient, py::object ao,
           py::object enhance, py::object fill) {
            const RenderArguments args{
                step,    view,   azimuth, elevation, tf, opacity_scale, segment_opacity,
                colours, source, lights,  ambient,   ao, enhance,       fill};
            const ExploreRequest request = viewer::request_from_options(options_of(args));
            Explorer& explorer = a.explore();
            py::gil_scoped_release release;
            return std::make_shared<ExploreFrame>(explorer.render(request));
        },
        py::arg("step"), py::kw_only(), py::arg("view") = 0, py::arg("azimuth") = py::none(),
        py::arg("elevation") = py::none(), py::arg("tf") = py::none(),
        py::arg("opacity_scale") = py::none(), py::arg("segment_opacity") = py::none(),
        py::arg("colours") = py::none(), py::arg("source") = py::none(),
        py::arg("lights") = py::none(), py::arg("ambient") = py::none(), py::arg("ao") = py::none(),
        py::arg("enhance") = py::none(), py::arg("fill") = py::none(),
        "Renders a frame of `step` from the stored view `view`, as insitu-view render does "
        "(the same options, parsed by the same code): azimuth/elevation (degrees) a new orbit "
        "view; tf an edited transfer function (TF JSON dict, or a path to a .json file); "
        "opacity_scale {interval: factor}; segment_opacity {segment: factor}; colours 'auto', "
        "'model' or 'recompose'; source 'auto', 'single', 'multi', 'lightfield' or 'volume'; "
        "lights a list of 'camera' or (azimuth, elevation[, diffuse[, specular]]); ambient; ao "
        "True, a radius in pixels or (radius, strength); enhance (lambda, gamma); fill the "
        "hole-filling radius. The OpenCL device opens on the first frame; the GIL is released "
        "while rendering.");

    module.def(
        "to_srgb8",
        [](const py::array_t<float, py::array::c_style | py::array::forcecast>& linear) {
            return srgb8_of(image_of(linear));
        },
        py::arg("linear"),
        "A linear float image (height, width[, channels]; 4 channels = premultiplied "
        "RGBA) as 8-bit sRGB, exactly as insitu-view render writes PNGs (uint8).");
    module.def(
        "read_exr",
        [](const std::string& path, const std::vector<std::string>& channels) {
            py::capsule owner(new Image(read_exr(path, channels)),
                              [](void* image) { delete static_cast<Image*>(image); });
            return image_view(*static_cast<Image*>(owner.get_pointer()), owner);
        },
        py::arg("path"), py::arg("channels") = std::vector<std::string>{"R", "G", "B", "A"},
        "Reads the named float channels of a single-part EXR (e.g. insitu-view render --out "
        "x.exr) into a float32 array (height, width, channels).");
}

}  // namespace insitu::python
