// libinsitu's typed errors (insitu/error.hpp) as Python exceptions of matching types: one base,
// insitu.Error, and a subclass per kind that also derives from the built-in exception a Python
// caller would catch for it (ValueError for bad arguments and text, OSError for files). The
// message is the library's, on one line (insitu::one_line), as every other boundary prints it.
#include <Python.h>

#include "bindings.hpp"
#include "insitu/core/check.hpp"
#include "insitu/error.hpp"

namespace insitu::python {

namespace {

struct PythonErrors {
    PyObject* error = nullptr;
    PyObject* invalid_argument = nullptr;
    PyObject* parse = nullptr;
    PyObject* compute = nullptr;
    PyObject* io = nullptr;
    PyObject* state = nullptr;
    PyObject* invariant = nullptr;
};

// Module-lifetime objects: the interpreter holds them through the module's attributes.
PythonErrors errors;

PyObject* make_error(py::module_& module, const char* name, const char* doc,
                     std::vector<PyObject*> bases) {
    py::tuple base_tuple(bases.size());
    for (std::size_t i = 0; i < bases.size(); ++i) {
        base_tuple[i] = py::reinterpret_borrow<py::object>(bases[i]);
    }
    const std::string qualified = std::string("insitu.") + name;
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base_tuple.ptr(), nullptr);
    if (type == nullptr) throw py::error_already_set();
    module.add_object(name, py::reinterpret_borrow<py::object>(type));
    return type;
}

void raise(PyObject* type, const std::exception& error) {
    PyErr_SetString(type, one_line(error.what()).c_str());
}

}  // namespace

void bind_errors(py::module_& module) {
    errors.error =
        make_error(module, "Error", "Base of every error libinsitu raises.", {PyExc_RuntimeError});
    errors.invalid_argument = make_error(
        module, "InvalidArgument",
        "An argument, configuration value or input outside what the API accepts; names it.",
        {errors.error, PyExc_ValueError});
    errors.parse = make_error(module, "ParseError",
                              "JSON or another text that cannot be parsed or has the wrong shape.",
                              {errors.error, PyExc_ValueError});
    errors.compute = make_error(
        module, "ComputeError",
        "OpenCL: no platform, device selection, kernel build or launch failed.", {errors.error});
    errors.io = make_error(module, "IoError",
                           "A file that cannot be opened, read, written or decoded; names it.",
                           {errors.error, PyExc_OSError});
    errors.state =
        make_error(module, "StateError", "A call in the wrong order, e.g. execute after finalize.",
                   {errors.error});
    errors.invariant = make_error(
        module, "InvariantError",
        "A broken internal invariant: a libinsitu bug (please report it).", {errors.error});
    // Most derived first: each C++ type is caught as itself before its base.
    py::register_exception_translator([](std::exception_ptr thrown) {
        try {
            if (thrown) std::rethrow_exception(thrown);
        } catch (const InvalidArgument& error) {
            raise(errors.invalid_argument, error);
        } catch (const ParseError& error) {
            raise(errors.parse, error);
        } catch (const ComputeError& error) {
            raise(errors.compute, error);
        } catch (const IoError& error) {
            raise(errors.io, error);
        } catch (const StateError& error) {
            raise(errors.state, error);
        } catch (const InvariantError& error) {
            raise(errors.invariant, error);
        } catch (const Error& error) {
            raise(errors.error, error);
        }
    });
}

}  // namespace insitu::python
