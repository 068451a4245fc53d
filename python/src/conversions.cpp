// Library values as Python values: JSON through Python's own json module (what comes back is
// plain dicts and lists, as json.load gives), images as numpy views of their pixels.
#include <algorithm>

#include "bindings.hpp"
#include "insitu/error.hpp"

namespace insitu::python {

py::object to_python(const nlohmann::json& value) {
    return py::module_::import("json").attr("loads")(value.dump());
}

nlohmann::json from_python(py::handle value, const std::string& what) {
    std::string text;
    try {
        text = py::module_::import("json")
                   .attr("dumps")(value, py::arg("allow_nan") = false)
                   .cast<std::string>();
    } catch (const py::error_already_set& error) {
        fail<InvalidArgument>(what, ": not JSON (", error.what(), ")");
    }
    return nlohmann::json::parse(text);
}

namespace {
void make_read_only(py::array& array) {
    py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
}
}  // namespace

py::array image_view(const Image& image, py::handle owner, bool squeeze) {
    const auto height = static_cast<py::ssize_t>(image.height);
    const auto width = static_cast<py::ssize_t>(image.width);
    const auto channels = static_cast<py::ssize_t>(image.channels);
    const auto item = static_cast<py::ssize_t>(sizeof(float));
    std::vector<py::ssize_t> shape{height, width, channels};
    std::vector<py::ssize_t> strides{width * channels * item, channels * item, item};
    if (squeeze && channels == 1) {
        shape.pop_back();
        strides.pop_back();
    }
    py::array array(py::dtype::of<float>(), shape, strides, image.pixels.data(), owner);
    make_read_only(array);
    return array;
}

py::array stack_images(const std::vector<Image>& images) {
    const int height = images.empty() ? 0 : images.front().height;
    const int width = images.empty() ? 0 : images.front().width;
    const auto count = static_cast<py::ssize_t>(images.size());
    py::array_t<float> stacked(
        {static_cast<py::ssize_t>(height), static_cast<py::ssize_t>(width), count});
    float* out = stacked.mutable_data();
    for (py::ssize_t k = 0; k < count; ++k) {
        const Image& image = images[static_cast<std::size_t>(k)];
        if (image.width != width || image.height != height || image.channels != 1) {
            fail<InvalidArgument>("stack_images: image ", k, " is ", image.width, "x", image.height,
                                  "x", image.channels, ", expected ", width, "x", height, "x1");
        }
        for (std::size_t p = 0; p < image.pixel_count(); ++p) {
            out[static_cast<py::ssize_t>(p) * count + k] = image.pixels[p];
        }
    }
    return std::move(stacked);
}

}  // namespace insitu::python
