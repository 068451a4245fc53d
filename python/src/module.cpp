// The Python module `insitu` (issue 44): see README "From Python" and python/insitu.pyi.
#include "bindings.hpp"

PYBIND11_MODULE(insitu, module) {
    module.doc() =
        "libinsitu from Python: open an archive (insitu.open) and read its steps, proxies, light "
        "fields and compressed fields as numpy arrays, render any frame as insitu-view render "
        "does (Archive.render), and instrument a simulation written with numpy "
        "(insitu.Instrument). Errors are insitu.Error subclasses carrying the library's message.";
    insitu::python::bind_errors(module);
    insitu::python::bind_archive(module);
    insitu::python::bind_frames(module);
    insitu::python::bind_cinema(module);
    insitu::python::bind_instrument(module);
}
