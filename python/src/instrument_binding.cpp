// insitu.Instrument: a simulation written in Python hands its numpy arrays over once per step.
// Nothing is copied: every array of uint8, uint16, int16, float32 or float64 in native byte
// order, C- or Fortran-ordered or any strided view with positive strides, becomes a Field over
// the array's own memory (indexed [x, y, z]); the GIL is released while the library works.
#include <optional>

#include "bindings.hpp"
#include "insitu/error.hpp"
#include "insitu/instrument.hpp"

namespace insitu::python {

namespace {

/// A field with its own grid (insitu.Field): the array and what the keywords of execute would
/// otherwise say for every array.
struct FieldSpec {
    py::array data;
    py::object ghost_layers = py::none();
    py::object spacing = py::none();
    py::object origin = py::none();
    py::object centering = py::none();
};

/// The grid keywords of execute, for the arrays given without a Field.
struct GridDefaults {
    py::object ghost_layers, spacing, origin, centering;
};

ScalarType scalar_type_of(const py::array& array, const std::string& name) {
    const py::dtype dtype = array.dtype();
    const char kind = dtype.kind();
    const auto size = dtype.itemsize();
    const char order = dtype.attr("byteorder").cast<std::string>().front();
    const bool native = order == '=' || order == '|';
    if (native && kind == 'f' && size == 4) return ScalarType::float32;
    if (native && kind == 'f' && size == 8) return ScalarType::float64;
    if (native && kind == 'i' && size == 2) return ScalarType::int16;
    if (native && kind == 'u' && size == 2) return ScalarType::uint16;
    if (kind == 'u' && size == 1) return ScalarType::uint8;
    fail<InvalidArgument>("field \"", name, "\": dtype ",
                          py::str(static_cast<const py::handle&>(dtype)).cast<std::string>(),
                          " (expected float32, float64, int16, uint16 or uint8 in native byte "
                          "order; convert with .astype(numpy.float32), a copy)");
}

Index3 triple(py::handle value, const std::string& what) {
    if (py::isinstance<py::int_>(value)) {
        const auto same = value.cast<std::int64_t>();
        return {same, same, same};
    }
    const auto items = value.cast<std::vector<std::int64_t>>();
    if (items.size() != 3) fail<InvalidArgument>(what, ": expected 3 values, got ", items.size());
    return {items[0], items[1], items[2]};
}

glm::dvec3 vector3(py::handle value, const std::string& what) {
    const auto items = value.cast<std::vector<double>>();
    if (items.size() != 3) fail<InvalidArgument>(what, ": expected 3 values, got ", items.size());
    return {items[0], items[1], items[2]};
}

/// `ghost_layers`: n, (nx, ny, nz), or ((low x, y, z), (high x, y, z)).
void set_ghost_layers(Field& field, py::handle layers, const std::string& name) {
    const std::string what = "field \"" + name + "\": ghost_layers";
    if (py::isinstance<py::int_>(layers)) {
        field.set_ghost_layers(layers.cast<std::int64_t>());
        return;
    }
    const auto parts = py::reinterpret_borrow<py::sequence>(layers);
    if (parts.size() == 2 && !py::isinstance<py::int_>(parts[0])) {
        field.set_ghost_layers(triple(parts[0], what), triple(parts[1], what));
    } else {
        const Index3 both = triple(layers, what);
        field.set_ghost_layers(both, both);
    }
}

Field field_of(const std::string& name, const py::array& array, const FieldSpec& spec,
               const GridDefaults& defaults) {
    if (array.ndim() != 3) {
        fail<InvalidArgument>("field \"", name, "\": an array of ", array.ndim(),
                              " dimensions (expected 3, indexed [x, y, z])");
    }
    const ScalarType type = scalar_type_of(array, name);
    const auto item = static_cast<py::ssize_t>(scalar_size_bytes(type));
    Index3 dims{}, strides{};
    for (int axis = 0; axis < 3; ++axis) {
        dims[axis] = array.shape(axis);
        const py::ssize_t stride = array.strides(axis);
        // A single sample's stride is never used: any positive one will do.
        if (dims[axis] == 1) {
            strides[axis] = 1;
            continue;
        }
        if (stride <= 0 || stride % item != 0) {
            fail<InvalidArgument>("field \"", name, "\": axis ", axis, " has a stride of ", stride,
                                  " bytes (a reversed, broadcast or unaligned view; pass "
                                  "numpy.ascontiguousarray(a), a copy)");
        }
        strides[axis] = stride / item;
    }
    Field field(name, array.data(), type, dims);
    field.set_strides(strides);
    const auto pick = [](const py::object& own, const py::object& fallback) {
        return own.is_none() ? fallback : own;
    };
    const py::object ghosts = pick(spec.ghost_layers, defaults.ghost_layers);
    const py::object spacing = pick(spec.spacing, defaults.spacing);
    const py::object origin = pick(spec.origin, defaults.origin);
    const py::object centering = pick(spec.centering, defaults.centering);
    if (!ghosts.is_none()) set_ghost_layers(field, ghosts, name);
    if (!spacing.is_none()) field.set_spacing(vector3(spacing, "field \"" + name + "\": spacing"));
    if (!origin.is_none()) field.set_origin(vector3(origin, "field \"" + name + "\": origin"));
    if (!centering.is_none())
        field.set_centering(parse_centering(py::str(centering).cast<std::string>()));
    return field;
}

/// The arrays kept referenced while the Fields view them, and the Fields.
struct HandedFields {
    std::vector<py::array> arrays;
    std::vector<Field> fields;
};

void add_block(HandedFields& handed, const std::string& name, py::handle value,
               const GridDefaults& defaults) {
    if (py::isinstance<FieldSpec>(value)) {
        const auto& spec = value.cast<const FieldSpec&>();
        handed.arrays.push_back(spec.data);
        handed.fields.push_back(field_of(name, spec.data, spec, defaults));
        return;
    }
    if (!py::isinstance<py::array>(value)) {
        fail<InvalidArgument>("field \"", name, "\": a ",
                              py::str(value.get_type().attr("__name__")).cast<std::string>(),
                              " (expected a numpy array, an insitu.Field or a list of them)");
    }
    handed.arrays.push_back(py::reinterpret_borrow<py::array>(value));
    handed.fields.push_back(field_of(name, handed.arrays.back(), FieldSpec{}, defaults));
}

HandedFields hand_over(const py::dict& fields, const GridDefaults& defaults) {
    HandedFields handed;
    for (const auto& [key, value] : fields) {
        const auto name = py::str(key).cast<std::string>();
        if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
            for (py::handle block : value) add_block(handed, name, block, defaults);
        } else {
            add_block(handed, name, value, defaults);
        }
    }
    return handed;
}

std::unique_ptr<Instrument> make_instrument(py::object config, bool raise_errors, bool log,
                                            py::object comm) {
    InstrumentOptions options;
    options.rethrow_errors = raise_errors;
    options.log = log;
    if (!comm.is_none()) options.communicator = communicator_of(comm);
    if (py::isinstance<py::dict>(config)) {
        const std::string text = from_python(config, "config").dump();
        py::gil_scoped_release release;
        return Instrument::from_json_text(text, options);
    }
    const auto path = py::str(py::module_::import("os").attr("fspath")(config)).cast<std::string>();
    py::gil_scoped_release release;
    return Instrument::from_json_file(path, options);
}

py::dict statistics_of(const Instrument& instrument) {
    const InstrumentStatistics s = instrument.statistics();
    py::dict out;
    out["steps_executed"] = s.steps_executed;
    out["steps_written"] = s.steps_written;
    out["steps_dropped"] = s.steps_dropped;
    out["steps_replayed"] = s.steps_replayed;
    out["errors"] = s.errors;
    out["bytes_written"] = s.bytes_written;
    out["compute_seconds"] = s.compute_seconds;
    out["blocked_seconds"] = s.blocked_seconds;
    out["write_seconds"] = s.write_seconds;
    out["execute_seconds"] = s.execute_seconds;
    out["simulation_seconds"] = s.simulation_seconds;
    out["nonfinite_samples"] = s.nonfinite_samples;
    out["composite_seconds"] = s.composite_seconds;
    return out;
}

Status execute(Instrument& instrument, std::int64_t step, double time, const py::dict& fields,
               const GridDefaults& defaults) {
    const HandedFields handed = hand_over(fields, defaults);
    py::gil_scoped_release release;
    return instrument.execute(step, time, handed.fields);
}

void bind_field(py::module_& module) {
    py::class_<FieldSpec>(module, "Field",
                          "A field with a grid of its own for Instrument.execute: the array "
                          "(3 dimensions indexed [x, y, z], any memory order, not copied) and "
                          "its ghost layers, spacing, origin (world units) and centring.")
        .def(py::init([](py::array data, py::object ghost_layers, py::object spacing,
                         py::object origin, py::object centering) {
                 return FieldSpec{std::move(data), std::move(ghost_layers), std::move(spacing),
                                  std::move(origin), std::move(centering)};
             }),
             py::arg("data"), py::kw_only(), py::arg("ghost_layers") = py::none(),
             py::arg("spacing") = py::none(), py::arg("origin") = py::none(),
             py::arg("centering") = py::none(),
             "ghost_layers: n, (nx, ny, nz) or ((low), (high)) samples skipped; spacing and "
             "origin: 3 world-unit values; centering: 'node' or 'cell'. Unset ones take "
             "execute's keywords.")
        .def_readonly("data", &FieldSpec::data, "The array (viewed, never copied).");
}

}  // namespace

void bind_instrument(py::module_& module) {
    py::enum_<Status>(module, "Status", "What Instrument.execute and finalize did.")
        .value("ok", Status::ok, "proxies computed and queued (or written)")
        .value("not_selected", Status::not_selected, "the cadence skipped this step")
        .value("dropped", Status::dropped, "writer queue full (when_full = drop)")
        .value("error", Status::error, "see Instrument.last_error; nothing written was lost");
    bind_field(module);
    py::class_<Instrument>(
        module, "Instrument",
        "What a simulation holds: made once from a configuration, handed the fields once per "
        "step. Failures of execute and finalize are a Status (and last_error), never an "
        "exception, unless raise_errors=True; the constructor raises on a bad configuration.")
        .def(py::init(&make_instrument), py::arg("config"), py::kw_only(),
             py::arg("raise_errors") = false, py::arg("log") = true, py::arg("comm") = py::none(),
             "config: a dict (the JSON configuration) or the path of a .json file. log: print "
             "warnings and finalize's summary to stderr. comm: an mpi4py communicator; then "
             "every rank of it constructs its Instrument (collective) and hands execute its own "
             "block(s) of each field (insitu.Field with origin and ghost layers).")
        .def(
            "execute",
            [](Instrument& instrument, std::int64_t step, double time, const py::dict& fields,
               py::object ghost_layers, py::object spacing, py::object origin,
               py::object centering) {
                return execute(instrument, step, time, fields,
                               {ghost_layers, spacing, origin, centering});
            },
            py::arg("step"), py::arg("time"), py::arg("fields"), py::kw_only(),
            py::arg("ghost_layers") = py::none(), py::arg("spacing") = py::none(),
            py::arg("origin") = py::none(), py::arg("centering") = py::none(),
            "One timestep: fields maps each configured field's name to a 3-D array indexed "
            "[x, y, z] (uint8, uint16, int16, float32, float64; C, Fortran or strided: viewed, "
            "not copied), an insitu.Field, or a list of them (blocks). The keywords apply to "
            "arrays given without a Field (as insitu.Field's). The arrays must not change until "
            "it returns; the GIL is released meanwhile. Returns a Status.")
        .def(
            "selects",
            [](const Instrument& instrument, std::int64_t step) {
                return instrument.selects(step);
            },
            py::arg("step"), "Whether execute(step, ...) would compute the step.")
        .def(
            "finalize",
            [](Instrument& instrument) {
                py::gil_scoped_release release;
                return instrument.finalize();
            },
            "Drains the writer and stops it; later execute calls return error.")
        .def_property_readonly("statistics", &statistics_of,
                               "The run's counts and times (InstrumentStatistics) as a dict.")
        .def_property_readonly("last_error", &Instrument::last_error,
                               "The most recent error message (empty if none).")
        .def_property_readonly("first_error", &Instrument::first_error,
                               "The run's first error: the root cause (empty if none).")
        .def_property_readonly(
            "config", [](const Instrument& i) { return to_python(i.config().to_json()); },
            "The configuration as validated, every default filled in.")
        .def("__enter__", [](py::object self) { return self; })
        .def(
            "__exit__",
            [](Instrument& instrument, py::args) {
                py::gil_scoped_release release;
                instrument.finalize();
            },
            "Finalizes.");
}

}  // namespace insitu::python
