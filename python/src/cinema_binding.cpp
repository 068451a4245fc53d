// Archive.export_cinema: chosen frames (steps x views x transfer functions x orbit angles) as a
// Cinema Spec D database, data.csv and one PNG a frame, which pycinema and Cinema:Explorer open.
// Each frame is Archive.render's (the same request, so the same pixels as insitu-view render)
// and each PNG is written by the library's write_png, whose pixels are Frame.srgb8().
#include <filesystem>
#include <fstream>

#include "bindings.hpp"
#include "insitu/core/image.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"

namespace insitu::python {

namespace {

/// `values` as a list, or [None] (one pass with the render's default) when it is None.
py::list choices(py::object values) {
    py::list out;
    if (values.is_none()) {
        out.append(py::none());
    } else {
        for (py::handle value : values) out.append(value);
    }
    return out;
}

/// A CSV and file-name cell: Python's str of a number (round-trips), or `absent` for None.
std::string cell(py::handle value, const std::string& absent) {
    return value.is_none()
               ? absent
               : py::str(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
}

/// Writes the frames of every combination and data.csv; returns the number of frames.
std::size_t export_cinema(py::object archive, const std::string& directory, py::object steps,
                          py::object views, py::object tfs, py::object azimuths,
                          py::object elevations) {
    const py::list step_list = steps.is_none() ? py::list(archive.attr("steps")) : choices(steps);
    const py::list view_list = views.is_none() ? py::list(py::make_tuple(0)) : choices(views);
    const py::list tf_list = choices(tfs), azimuth_list = choices(azimuths),
                   elevation_list = choices(elevations);
    std::filesystem::create_directories(directory);
    std::ofstream csv(directory + "/data.csv");
    // Spec D: the parameters, then FILE; tf is the position in `tfs` (-1: the stored function),
    // azimuth and elevation empty where the stored view's camera is used.
    csv << "step,view,tf,azimuth,elevation,FILE\n";
    std::size_t frames = 0;
    for (py::handle step : step_list) {
        for (py::handle view : view_list) {
            for (std::size_t t = 0; t < tf_list.size(); ++t) {
                for (py::handle azimuth : azimuth_list) {
                    for (py::handle elevation : elevation_list) {
                        py::object frame = archive.attr("render")(
                            step, py::arg("view") = view, py::arg("azimuth") = azimuth,
                            py::arg("elevation") = elevation, py::arg("tf") = tf_list[t]);
                        const std::string tf = tfs.is_none() ? "-1" : std::to_string(t);
                        const std::string name = "step" + py::str(step).cast<std::string>() +
                                                 "_view" + py::str(view).cast<std::string>() +
                                                 "_tf" + tf + "_az" + cell(azimuth, "stored") +
                                                 "_el" + cell(elevation, "stored") + ".png";
                        write_png(directory + "/" + name, frame.cast<ExploreFrame&>().colour);
                        csv << py::str(step).cast<std::string>() << ','
                            << py::str(view).cast<std::string>() << ',' << tf << ','
                            << cell(azimuth, "") << ',' << cell(elevation, "") << ',' << name
                            << '\n';
                        ++frames;
                    }
                }
            }
        }
    }
    csv.close();
    if (!csv) fail<IoError>("export_cinema: cannot write ", directory, "/data.csv");
    return frames;
}

}  // namespace

void bind_cinema(py::module_& module) {
    py::object archive = module.attr("Archive");
    py::cpp_function method(
        [](py::object self, py::object directory, py::object steps, py::object views,
           py::object tfs, py::object azimuths, py::object elevations) {
            const auto path = py::str(py::module_::import("os").attr("fspath")(directory));
            return export_cinema(self, path.cast<std::string>(), steps, views, tfs, azimuths,
                                 elevations);
        },
        py::name("export_cinema"), py::is_method(archive), py::arg("directory"), py::kw_only(),
        py::arg("steps") = py::none(), py::arg("views") = py::none(), py::arg("tfs") = py::none(),
        py::arg("azimuths") = py::none(), py::arg("elevations") = py::none(),
        "Writes a Cinema Spec D database into `directory` (name it *.cdb for Cinema tools): one "
        "PNG per combination of steps (default: all) x views (stored view indexes, default [0]) "
        "x tfs (transfer functions as render's tf; default: the stored one) x azimuths x "
        "elevations (degrees; default: the stored view's camera), each rendered by render() and "
        "written as srgb8(), and data.csv with the columns step, view, tf (position in tfs, -1 "
        "for the stored function), azimuth, elevation, FILE. Returns the number of frames.");
    archive.attr("export_cinema") = method;
}

}  // namespace insitu::python
