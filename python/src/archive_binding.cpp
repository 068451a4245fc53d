// insitu.open and the archive object's reading side: steps, times, fields, views, the manifest,
// the damage list; a view's proxies, a step's light fields and compressed fields as numpy arrays.
// Images are returned as views of the reader's buffers (no copy) except where the library keeps
// one image per layer (depth layers, distortion), which are stacked into one array (a copy).
#include <algorithm>
#include <cstdio>
#include <map>
#include <utility>

#include "archive.hpp"
#include "bindings.hpp"
#include "insitu/error.hpp"

namespace insitu::python {

namespace {

/// A view's proxies as the reader loaded them, kept alive by the arrays that view them.
struct Proxies {
    ProxyFrame frame;
    std::int64_t step = 0;
    int view = 0;
};

/// One proxy of a view: the image (or the layers stacked) and its channels as the archive's EXR
/// names them (src/archive/archive_format.hpp: every channel starts with its part's name).
struct ProxyEntry {
    std::string name;
    std::vector<std::string> channels;
    const Image* image = nullptr;                ///< viewed in place
    const std::vector<Image>* layers = nullptr;  ///< stacked (a copy)
};

std::vector<std::string> numbered(const std::string& prefix, int count, bool two_digits) {
    std::vector<std::string> names;
    for (int i = 0; i < count; ++i) {
        char index[16];
        std::snprintf(index, sizeof(index), two_digits ? "%02d" : "%d", i);
        names.push_back(prefix + index);
    }
    return names;
}

std::vector<std::string> rgba(const std::string& part) {
    return {part + ".R", part + ".G", part + ".B", part + ".A"};
}

std::vector<ProxyEntry> proxy_entries(const ProxyFrame& frame) {
    const std::string multi = frame.multi_perspective ? "multi." : "";
    const std::string attenuation = multi + "attenuation";
    std::vector<ProxyEntry> entries;
    const auto image = [&](const char* name, const Image& source, std::vector<std::string> names) {
        if (source.channels > 0) entries.push_back({name, std::move(names), &source, nullptr});
    };
    const auto layers = [&](const char* name, const std::vector<Image>& source,
                            const std::string& part) {
        const int count = static_cast<int>(source.size());
        if (count > 0)
            entries.push_back({name, numbered(part + ".layer", count, false), nullptr, &source});
    };
    layers("depth", frame.depth_layers, multi + "depth");
    layers("distortion", frame.distortion_layers, multi + "distortion");
    image("attenuation", frame.attenuation,
          numbered(attenuation + ".a", frame.attenuation.channels, true));
    image("mean_depth", frame.mean_depth,
          numbered(attenuation + ".zmean", frame.mean_depth.channels, true));
    image("optical_depth", frame.optical_depth,
          numbered(attenuation + ".tau", frame.optical_depth.channels, true));
    image("entry_depth", frame.entry_depth,
          numbered(attenuation + ".zentry", frame.entry_depth.channels, true));
    image("interleaving", frame.interleaving,
          {attenuation + ".reentries", attenuation + ".reentered"});
    image("rendering", frame.rendering, rgba("rendering"));
    for (std::size_t k = 0; k < frame.training.size(); ++k) {
        const std::string part = "train" + std::to_string(k);
        if (frame.training[k].channels > 0) {
            entries.push_back({part, rgba(part), &frame.training[k], nullptr});
        }
    }
    return entries;
}

const ProxyEntry& find_entry(const std::vector<ProxyEntry>& entries, const std::string& name,
                             const Proxies& proxies) {
    for (const ProxyEntry& entry : entries) {
        if (entry.name == name) return entry;
    }
    std::string present;
    for (const ProxyEntry& entry : entries) present += (present.empty() ? "" : ", ") + entry.name;
    fail<InvalidArgument>("proxy \"", name, "\": step ", proxies.step, " view ", proxies.view,
                          " holds ", present.empty() ? "none" : present);
}

/// Keeps `value` alive for as long as a numpy array based on the returned capsule lives.
template <typename T>
py::capsule own(T&& value) {
    auto* held = new std::decay_t<T>(std::forward<T>(value));
    return py::capsule(held, [](void* pointer) { delete static_cast<std::decay_t<T>*>(pointer); });
}

py::object intervals_of(const std::optional<IntervalSet>& intervals) {
    if (!intervals) return py::none();
    return py::cast(intervals->edges());
}

void bind_proxies(py::module_& module) {
    py::class_<Proxies, std::shared_ptr<Proxies>>(
        module, "Proxies",
        "The proxies of one stored view at one step (Archive.proxies), by name: depth, "
        "distortion, attenuation, mean_depth, optical_depth, entry_depth, interleaving, "
        "rendering, train<k> (those the archive holds). Each is a read-only float32 array "
        "(height, width, channels), pixel (0, 0) top-left; a view of the reader's buffer, except "
        "depth and distortion, whose layers are stacked into a new array.")
        .def_readonly("step", &Proxies::step, "The step.")
        .def_readonly("view", &Proxies::view, "The stored view's index.")
        .def_property_readonly(
            "multi_perspective", [](const Proxies& p) { return p.frame.multi_perspective; },
            "Whether these are the multi-perspective proxies (channels named multi.*).")
        .def(
            "keys",
            [](const Proxies& p) {
                std::vector<std::string> names;
                for (const ProxyEntry& entry : proxy_entries(p.frame)) names.push_back(entry.name);
                return names;
            },
            "The names of the proxies present.")
        .def("__contains__",
             [](const Proxies& p, const std::string& name) {
                 for (const ProxyEntry& entry : proxy_entries(p.frame)) {
                     if (entry.name == name) return true;
                 }
                 return false;
             })
        .def(
            "__getitem__",
            [](py::object self, const std::string& name) -> py::array {
                const Proxies& p = self.cast<const Proxies&>();
                const std::vector<ProxyEntry> entries = proxy_entries(p.frame);
                const ProxyEntry& entry = find_entry(entries, name, p);
                return entry.image ? image_view(*entry.image, self) : stack_images(*entry.layers);
            },
            "The proxy `name` as a float32 array (height, width, channels).")
        .def(
            "channels",
            [](const Proxies& p, const std::string& name) {
                return find_entry(proxy_entries(p.frame), name, p).channels;
            },
            "The channel names of proxy `name`, as the archive's EXR part names them.")
        .def_property_readonly(
            "isovalues", [](const Proxies& p) { return p.frame.isovalues; },
            "The depth layers' isovalues, in field units.")
        .def_property_readonly(
            "intervals", [](const Proxies& p) { return intervals_of(p.frame.intervals); },
            "The value intervals' edges (L + 1, field units), or None without attenuation.")
        .def_property_readonly(
            "camera", [](const Proxies& p) { return to_python(p.frame.camera.to_json()); },
            "The stored camera, as the archive's JSON describes it.");
}

/// One step's light field of one field (Archive.light_field).
struct LightFieldData {
    LightField light_field;
};

py::dict camera_images(py::object self, int camera) {
    const LightField& light_field = self.cast<const LightFieldData&>().light_field;
    const LightFieldImages* images = light_field.find(camera);
    if (images == nullptr) {
        fail<InvalidArgument>("light-field camera ", camera, " is not held (rig of ",
                              light_field.rig.camera_count(), " cameras; held: see .cameras)");
    }
    py::dict out;
    for (std::size_t s = 0; s < images->segment_rgba.size(); ++s) {
        out[py::str("segment" + std::to_string(s))] = image_view(images->segment_rgba[s], self);
    }
    for (std::size_t s = 0; s < images->segment_depth.size(); ++s) {
        out[py::str("segment" + std::to_string(s) + ".depth")] =
            image_view(images->segment_depth[s], self, true);
    }
    if (images->depth.channels > 0) out["depth"] = image_view(images->depth, self, true);
    if (images->attenuation.channels > 0) {
        out["attenuation"] = image_view(images->attenuation, self);
    }
    if (images->mean_depth.channels > 0) out["mean_depth"] = image_view(images->mean_depth, self);
    return out;
}

void bind_light_field(py::module_& module) {
    py::class_<LightFieldData, std::shared_ptr<LightFieldData>>(
        module, "LightField",
        "One step's light field of one field (Archive.light_field): per camera of the rig a "
        "parabolic map of premultiplied RGBA per segment and first-hit depth (secant fraction, "
        "inf where nothing was hit), and with attenuation a_j and mean depths per interval.")
        .def_property_readonly(
            "cameras",
            [](const LightFieldData& d) {
                std::vector<int> held;
                for (const LightFieldImages& images : d.light_field.cameras) {
                    held.push_back(images.camera);
                }
                return held;
            },
            "The indices of the cameras read (all of the file's unless some were asked).")
        .def_property_readonly(
            "rig", [](const LightFieldData& d) { return to_python(d.light_field.rig.to_json()); },
            "The camera rig (positions, map size), as the archive's JSON describes it.")
        .def_property_readonly(
            "settings",
            [](const LightFieldData& d) { return to_python(d.light_field.settings.to_json()); },
            "The light field's settings as configured.")
        .def_property_readonly(
            "transfer_function",
            [](const LightFieldData& d) {
                return to_python(d.light_field.transfer_function.to_json());
            },
            "The transfer function it was captured with (TF JSON as a dict).")
        .def_property_readonly(
            "isovalues", [](const LightFieldData& d) { return d.light_field.isovalues; },
            "The segments' split values (segments \"layers\").")
        .def_property_readonly(
            "intervals",
            [](const LightFieldData& d) { return intervals_of(d.light_field.intervals); },
            "The value intervals' edges of the attenuation light field, or None.")
        .def_property_readonly(
            "segment_count", [](const LightFieldData& d) { return d.light_field.segment_count(); },
            "Segments per ray.")
        .def("camera", &camera_images, py::arg("index"),
             "Camera `index`'s images as a dict of read-only float32 views: segment<s> (RGBA), "
             "segment<s>.depth (more than one segment), depth, attenuation, mean_depth.");
}

std::vector<std::int64_t> archive_steps(const Archive& a) {
    return a.reader->steps();
}

std::vector<double> archive_times(const Archive& a) {
    // One pass over the index (a 10 000-step archive opens in well under a second).
    std::map<std::int64_t, double> time_of;
    for (const auto& entry : a.reader->manifest().at("steps")) {
        time_of[entry.at("step").get<std::int64_t>()] = entry.at("time").get<double>();
    }
    std::vector<double> times;
    for (const std::int64_t step : a.reader->steps()) times.push_back(time_of.at(step));
    return times;
}

py::list archive_views(const Archive& a) {
    py::list views;
    const std::vector<std::int64_t> steps = a.reader->steps();
    if (steps.empty()) return views;
    for (const auto& entry : a.reader->manifest().at("steps")) {
        if (entry.at("step").get<std::int64_t>() != steps.front()) continue;
        for (const auto& view : entry.at("views")) {
            py::dict out;
            out["view"] = view.at("view").get<int>();
            out["field"] = view.value("field", entry.at("field").get<std::string>());
            out["azimuth"] = view.value("phi", 0.0);
            out["elevation"] = view.value("theta", 0.0);
            views.append(out);
        }
    }
    return views;
}

py::list archive_fields(const Archive& a) {
    py::list fields;
    std::vector<std::string> seen;
    for (const auto& view : archive_views(a)) {
        const auto name = view["field"].cast<std::string>();
        if (std::find(seen.begin(), seen.end(), name) != seen.end()) continue;
        seen.push_back(name);
        fields.append(name);
    }
    return fields;
}

py::dict volume_entry(const ArchivedVolume& volume) {
    py::dict out;
    out["field"] = volume.field;
    out["codec"] = volume.codec;
    out["mode"] = volume.mode == VolumeMode::accuracy ? "accuracy" : "rate";
    out["tolerance"] = volume.tolerance;
    out["rate"] = volume.rate;
    out["dims"] = py::make_tuple(volume.dims[0], volume.dims[1], volume.dims[2]);
    out["min"] = volume.min;
    out["max"] = volume.max;
    out["nonfinite"] = volume.nonfinite;
    out["blocks"] = volume.blocks;
    out["bytes"] = volume.bytes;
    out["files"] = volume.files;
    return out;
}

py::array volume_array(Archive& a, std::int64_t step, const std::string& field_or_empty) {
    std::string field = field_or_empty;
    if (field.empty()) {
        const std::vector<ArchivedVolume> volumes = a.reader->volumes(step);
        if (volumes.empty()) fail<InvalidArgument>("step ", step, " holds no compressed field");
        field = volumes.front().field;
    }
    VolumeGrid grid;
    {
        py::gil_scoped_release release;
        grid = a.reader->load_volume(step, field);
    }
    py::capsule owner = own(std::move(grid));
    const auto& held = *static_cast<VolumeGrid*>(owner.get_pointer());
    const auto nx = static_cast<py::ssize_t>(held.dims[0]);
    const auto ny = static_cast<py::ssize_t>(held.dims[1]);
    const auto nz = static_cast<py::ssize_t>(held.dims[2]);
    const auto item = static_cast<py::ssize_t>(sizeof(float));
    // (x, y, z) indexing over the x-fastest values: a Fortran-ordered view, no copy.
    return py::array(py::dtype::of<float>(), {nx, ny, nz}, {item, item * nx, item * nx * ny},
                     held.values.data(), owner);
}

}  // namespace

void bind_archive_methods(py::class_<Archive, std::shared_ptr<Archive>>& archive);
void bind_archive_representations(py::class_<Archive, std::shared_ptr<Archive>>& archive);

void bind_archive(py::module_& module) {
    bind_proxies(module);
    bind_light_field(module);
    py::class_<Archive, std::shared_ptr<Archive>> archive(
        module, "Archive",
        "An archive a run wrote (insitu.open): its index read once; proxies, light fields and "
        "compressed fields read from their files when asked; frames rendered by render().");
    bind_archive_methods(archive);
    module.def(
        "open",
        [](const std::string& path, bool damaged) {
            auto archive = std::make_shared<Archive>();
            archive->path = path;
            archive->damaged = damaged;
            py::gil_scoped_release release;
            archive->reader = std::make_shared<ArchiveReader>(
                damaged ? ArchiveReader::open_damaged(path) : ArchiveReader(path));
            return archive;
        },
        py::arg("path"), py::arg("damaged") = false,
        "Opens the archive at `path` and reads its index (IoError/ParseError name the file). "
        "damaged=True opens what is readable of a damaged archive (its problems: "
        "Archive.damage()), as insitu-view info does.");
}

void bind_archive_methods(py::class_<Archive, std::shared_ptr<Archive>>& archive) {
    archive.def_readonly("path", &Archive::path, "The archive's folder, as given.")
        .def_property_readonly("steps", &archive_steps, "The archived steps, increasing.")
        .def_property_readonly("times", &archive_times, "The simulation time of each step.")
        .def_property_readonly("fields", &archive_fields, "The names of the fields shown.")
        .def_property_readonly("views", &archive_views,
                               "The stored views: dicts of view, field, azimuth, elevation "
                               "(degrees), as the first step holds them.")
        .def_property_readonly(
            "manifest", [](const Archive& a) { return to_python(a.reader->manifest()); },
            "manifest.json (with the journal's steps) as a dict; built on each access.")
        .def_property_readonly(
            "diagnostics", [](const Archive& a) { return a.reader->diagnostics(); },
            "One line per problem of the index (skipped step entries; empty when sound).")
        .def(
            "damage",
            [](const Archive& a) {
                py::gil_scoped_release release;
                return a.reader->check().problems;
            },
            "Checks every file the index names (size, CRC-32, data.csv) and returns one line "
            "per problem, each naming its file (empty: intact). Reads every file once.")
        .def(
            "refresh",
            [](Archive& a) {
                a.reader = std::make_shared<ArchiveReader>(
                    a.damaged ? ArchiveReader::open_damaged(a.path) : ArchiveReader(a.path));
                if (a.explorer) a.explorer->refresh();
            },
            "Re-reads the index, so steps a running simulation wrote since appear.")
        .def(
            "transfer_function",
            [](const Archive& a, std::int64_t step, int view) {
                return to_python(a.reader->transfer_function(step, view).to_json());
            },
            py::arg("step"), py::arg("view") = 0,
            "The transfer function (step, view) was made with, as a TF JSON dict.")
        .def(
            "proxies",
            [](const Archive& a, std::int64_t step, int view, bool multi) {
                auto proxies = std::make_shared<Proxies>();
                proxies->step = step;
                proxies->view = view;
                py::gil_scoped_release release;
                proxies->frame = a.reader->load(step, view, multi);
                return proxies;
            },
            py::arg("step"), py::arg("view") = 0, py::arg("multi") = false,
            "Reads the single- (or multi-) perspective proxies of (step, view) from their EXR "
            "(checked against the index first): a Proxies mapping.")
        .def(
            "preview",
            [](const Archive& a, std::int64_t step, int view) {
                py::capsule owner = own(a.reader->load_preview(step, view));
                return image_view(*static_cast<Image*>(owner.get_pointer()), owner);
            },
            py::arg("step"), py::arg("view") = 0,
            "The preview PNG as linear premultiplied float32 (height, width, channels).");
    bind_archive_representations(archive);
}

void bind_archive_representations(py::class_<Archive, std::shared_ptr<Archive>>& archive) {
    archive
        .def(
            "light_fields",
            [](const Archive& a, std::int64_t step) {
                py::list out;
                for (const ArchivedLightField& lf : a.reader->light_fields(step)) {
                    out.append(
                        py::dict(py::arg("field") = lf.field, py::arg("cameras") = lf.cameras,
                                 py::arg("map_size") = lf.map_size, py::arg("path") = lf.exr_path));
                }
                return out;
            },
            py::arg("step"), "The step's light fields: dicts of field, cameras, map_size, path.")
        .def(
            "light_field",
            [](const Archive& a, std::int64_t step, const std::string& field,
               const std::vector<int>& cameras) {
                auto data = std::make_shared<LightFieldData>();
                py::gil_scoped_release release;
                data->light_field = a.reader->load_light_field(step, field, cameras);
                return data;
            },
            py::arg("step"), py::arg("field"), py::arg("cameras") = std::vector<int>{},
            "Reads the light field of (step, field): the cameras listed (all when empty).")
        .def(
            "volumes",
            [](const Archive& a, std::int64_t step) {
                py::list out;
                for (const ArchivedVolume& volume : a.reader->volumes(step)) {
                    out.append(volume_entry(volume));
                }
                return out;
            },
            py::arg("step"),
            "The step's compressed fields: dicts of field, codec, mode, tolerance, rate, dims, "
            "min, max, nonfinite, blocks, bytes, files.")
        .def("volume", &volume_array, py::arg("step"), py::arg("field") = "",
             "Decodes the compressed field of (step, field) (the first one when field is empty) "
             "into a float32 array indexed [x, y, z] (Fortran order, the decoder's own buffer: "
             "no copy), NaN where the field was NaN/Inf.")
        .def("__repr__", [](const Archive& a) {
            return "<insitu.Archive " + a.path + ": " + std::to_string(a.reader->steps().size()) +
                   " steps>";
        });
}

}  // namespace insitu::python
