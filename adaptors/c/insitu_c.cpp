// The C API (insitu.h) over insitu::Instrument.
//
// The one place where libinsitu's typed exceptions become status codes (STYLE.md, the CLBlast
// row): every extern "C" function runs its body through guarded(), which catches everything and
// records the message in a thread_local string for insitu_last_error(). No exception may cross
// into C or Fortran: unwinding through frames compiled without exception tables is undefined.
#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "insitu.h"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
#include "insitu_c_internal.hpp"

// The opaque handle of insitu.h.
struct insitu_instrument {
    std::unique_ptr<insitu::Instrument> instrument;
    // Blocks handed over since the last execute, by field name: insitu_set_field replaces a
    // field's blocks (setting it twice before one execute does not pass it twice),
    // insitu_add_block appends one (the tiles of a rank).
    std::map<std::string, std::vector<insitu::Field>> pending_fields;
    // Set by insitu_finalize: later set_field/execute calls are a caller bug (INSITU_ERROR_STATE),
    // caught here before a stale field pointer is stored.
    bool finalized = false;
};

namespace {

// Per thread, so that two threads driving two instruments do not overwrite each other's message.
thread_local std::string last_error_message;
// insitu_name_next_call: the entry name a language binding's user called, for the next call.
thread_local std::string next_call_name;
// Set once a create failed in this process: later calls given the NULL instrument that create
// left are silent no-ops (insitu.h), instead of one "instrument is NULL" per step.
std::atomic<bool> startup_failed{false};

// The name the current call reports: the binding's entry name when one was given, else the C
// function's. Consumed, so it applies to one call.
std::string call_name(const char* function) {
    std::string name = next_call_name.empty() ? std::string(function) : next_call_name;
    next_call_name.clear();
    return name;
}

using insitu::StateError;

// Records `function: message` for insitu_last_error() and returns `code`. Never throws: if even
// the message cannot be allocated, the code still reaches the caller (with an empty message).
int fail_with(int code, const char* function, const char* message) noexcept {
    try {
        last_error_message = std::string(function) + ": " + message;
    } catch (...) {
        last_error_message.clear();
    }
    return code;
}

int fail_with(int code, const char* function, const std::string& message) noexcept {
    return fail_with(code, function, message.c_str());
}

template <typename Pointer>
void require_not_null(Pointer* pointer, const char* argument) {
    if (pointer == nullptr) insitu::fail<insitu::InvalidArgument>(argument, " is NULL");
}

insitu::ScalarType scalar_type_from_c(int scalar_type) {
    switch (scalar_type) {
        case INSITU_UINT8:
            return insitu::ScalarType::uint8;
        case INSITU_UINT16:
            return insitu::ScalarType::uint16;
        case INSITU_INT16:
            return insitu::ScalarType::int16;
        case INSITU_FLOAT32:
            return insitu::ScalarType::float32;
        case INSITU_FLOAT64:
            return insitu::ScalarType::float64;
        default:
            insitu::fail<insitu::InvalidArgument>(
                "scalar_type = ", scalar_type,
                " is not one of INSITU_UINT8 (0), INSITU_UINT16 (1), INSITU_INT16 (2), "
                "INSITU_FLOAT32 (3), INSITU_FLOAT64 (4)");
    }
}

// The C status of each kind of error, for what guarded() catches and for the failures that
// Instrument::execute/finalize report as Status::error plus last_error() and last_error_kind()
// (the Instrument is made with rethrow_errors = false: the simulation is sacred).
int code_for_kind(insitu::ErrorKind kind) {
    switch (kind) {
        case insitu::ErrorKind::invalid_argument:
            return INSITU_ERROR_INVALID_ARGUMENT;
        case insitu::ErrorKind::parse:
            return INSITU_ERROR_PARSE;
        case insitu::ErrorKind::compute:
            return INSITU_ERROR_COMPUTE;
        case insitu::ErrorKind::io:
            return INSITU_ERROR_IO;
        case insitu::ErrorKind::state:
            return INSITU_ERROR_STATE;
        case insitu::ErrorKind::none:
        case insitu::ErrorKind::unknown:
            break;
    }
    return INSITU_ERROR_UNKNOWN;
}

// Runs `body` (which returns a status code) and turns any exception into the code of its kind
// (insitu::classify; other insitu::Error, std::bad_alloc, ... are INSITU_ERROR_UNKNOWN) and a
// message prefixed with the C function's name.
template <typename Body>
int guarded(const char* c_function, Body&& body) noexcept {
    std::string function;
    try {
        function = call_name(c_function);
    } catch (...) {
        function.clear();  // no memory for a name: report under none rather than throw
    }
    try {
        return body();
    } catch (const std::exception& error) {
        const int code = code_for_kind(insitu::classify(std::current_exception()));
        return fail_with(code, function.c_str(), error.what());
    } catch (...) {
        return fail_with(INSITU_ERROR_UNKNOWN, function.c_str(), "unknown exception");
    }
}

// True when `instrument` is the NULL a failed create left: the call is then a silent no-op.
bool after_failed_startup(const insitu_instrument* instrument) {
    return instrument == nullptr && startup_failed.load();
}

enum class Call { execute, finalize };

int code_for_status(insitu::Status status, const insitu::Instrument& instrument, Call call) {
    switch (status) {
        case insitu::Status::ok:
            return INSITU_OK;
        case insitu::Status::not_selected:
            return INSITU_NOT_SELECTED;
        case insitu::Status::dropped:
            return INSITU_DROPPED;
        case insitu::Status::error:
            break;
    }
    std::string message = instrument.last_error();
    if (message.empty()) message = "failed without a message";
    const int code = code_for_kind(instrument.last_error_kind());
    return fail_with(code, call == Call::execute ? "insitu_execute" : "insitu_finalize", message);
}

int create(const char* function, insitu_instrument** out,
           std::unique_ptr<insitu::Instrument> (*make)(const std::string&,
                                                       insitu::InstrumentOptions),
           const char* argument_name, const char* argument,
           const std::function<void(insitu::InstrumentOptions&)>& add_options = {}) {
    return guarded(function, [&]() -> int {
        require_not_null(out, "out");
        *out = nullptr;  // defined on failure too, so the caller may destroy it unconditionally
        require_not_null(argument, argument_name);
        insitu::InstrumentOptions options;
        // The simulation is sacred: execute()/finalize() report status instead of throwing.
        // The constructor still throws for a bad configuration; guarded() turns that into a code.
        options.rethrow_errors = false;
        auto handle = std::make_unique<insitu_instrument>();
        try {
            if (add_options) add_options(options);  // another adaptor's, insitu_c_internal.hpp
            handle->instrument = make(argument, options);
        } catch (...) {
            // The caller says it once, from insitu_last_error() (the library prints nothing, so
            // the message is not doubled); every later call on the NULL handle is a silent no-op.
            startup_failed = true;
            throw;
        }
        *out = handle.release();
        return INSITU_OK;
    });
}

enum class Blocks { replace, append };

// Checked at the hand-over rather than left to execute, so the message points at the call that
// passed the wrong name and the run need not reach a selected step to find out.
void require_configured_field(const insitu::Instrument& instrument, const char* name) {
    bool known = false;
    std::string names;
    for (const auto& field_name : instrument.config().fields) {
        known = known || field_name == name;
        names += (names.empty() ? "\"" : ", \"") + field_name + "\"";
    }
    if (!known) {
        insitu::fail<insitu::InvalidArgument>(
            "field \"", name, "\" is not in the configuration's fields (", names, ")");
    }
}

// The block a C caller describes, as a Field; a NULL origin, spacing, strides or ghost layers
// keeps Field's default.
insitu::Field block_field(const char* name, const void* data, int scalar_type,
                          const int64_t dims[3], const double origin[3], const double spacing[3],
                          const int64_t ghosts_low[3], const int64_t ghosts_high[3],
                          const int64_t strides[3], int centering) {
    if (centering != INSITU_NODE && centering != INSITU_CELL) {
        insitu::fail<insitu::InvalidArgument>("centering = ", centering,
                                              " is not INSITU_NODE (0) or INSITU_CELL (1)");
    }
    const insitu::ScalarType type = scalar_type_from_c(scalar_type);
    insitu::Field field(name, data, type, {dims[0], dims[1], dims[2]});
    field.set_centering(centering == INSITU_CELL ? insitu::Centering::cell
                                                 : insitu::Centering::node);
    if (origin != nullptr) field.set_origin({origin[0], origin[1], origin[2]});
    if (spacing != nullptr) field.set_spacing({spacing[0], spacing[1], spacing[2]});
    if (strides != nullptr) field.set_strides({strides[0], strides[1], strides[2]});
    if (ghosts_low != nullptr) {
        const insitu::Index3 low{ghosts_low[0], ghosts_low[1], ghosts_low[2]};
        const insitu::Index3 high =
            ghosts_high == nullptr ? low
                                   : insitu::Index3{ghosts_high[0], ghosts_high[1], ghosts_high[2]};
        field.set_ghost_layers(low, high);
    } else if (ghosts_high != nullptr) {
        field.set_ghost_layers({0, 0, 0}, {ghosts_high[0], ghosts_high[1], ghosts_high[2]});
    }
    return field;
}

int add_block(const char* function, insitu_instrument* instrument, const char* name,
              const void* data, int scalar_type, const int64_t dims[3], const double origin[3],
              const double spacing[3], const int64_t ghosts_low[3], const int64_t ghosts_high[3],
              const int64_t strides[3], int centering, Blocks blocks) {
    if (after_failed_startup(instrument)) return INSITU_NOT_SELECTED;
    const int status = guarded(function, [&]() -> int {
        require_not_null(instrument, "instrument");
        require_not_null(name, "name");
        require_not_null(data, "data");
        require_not_null(dims, "dims");
        if (instrument->finalized) {
            throw StateError(std::string("field \"") + name + "\" set after insitu_finalize");
        }
        require_configured_field(*instrument->instrument, name);
        insitu::Field field = block_field(name, data, scalar_type, dims, origin, spacing,
                                          ghosts_low, ghosts_high, strides, centering);
        std::vector<insitu::Field>& pending = instrument->pending_fields[name];
        if (blocks == Blocks::replace) pending.clear();
        pending.push_back(std::move(field));
        return INSITU_OK;
    });
    // A failed hand-over is an error of the run: counted, and kept as the root cause should the
    // step then fail for want of the field.
    if (status < 0 && instrument != nullptr && instrument->instrument) {
        try {
            instrument->instrument->report_error(last_error_message,
                                                 status == INSITU_ERROR_STATE
                                                     ? insitu::ErrorKind::state
                                                     : insitu::ErrorKind::invalid_argument);
        } catch (...) {
            // Counting must not turn a reported failure into a crash.
        }
    }
    return status;
}

}  // namespace

int insitu::c_api::create_with_options(
    const char* entry, const char* argument_name, const char* argument, bool is_path,
    const std::function<void(insitu::InstrumentOptions&)>& add_options, insitu_instrument** out) {
    return create(
        entry, out,
        is_path ? &insitu::Instrument::from_json_file : &insitu::Instrument::from_json_text,
        argument_name, argument, add_options);
}

extern "C" {

int insitu_create_from_file(const char* path, insitu_instrument** out) {
    return create("insitu_create_from_file", out, &insitu::Instrument::from_json_file, "path",
                  path);
}

int insitu_create_from_json(const char* json_text, insitu_instrument** out) {
    return create("insitu_create_from_json", out, &insitu::Instrument::from_json_text, "json_text",
                  json_text);
}

int insitu_set_field(insitu_instrument* instrument, const char* name, const void* data,
                     int scalar_type, const int64_t dims[3], const double origin[3],
                     const double spacing[3], const int64_t ghosts[3]) {
    return add_block("insitu_set_field", instrument, name, data, scalar_type, dims, origin, spacing,
                     ghosts, nullptr, nullptr, INSITU_NODE, Blocks::replace);
}

int insitu_set_field_strided(insitu_instrument* instrument, const char* name, const void* data,
                             int scalar_type, const int64_t dims[3], const double origin[3],
                             const double spacing[3], const int64_t ghosts[3],
                             const int64_t strides_samples[3]) {
    return add_block("insitu_set_field_strided", instrument, name, data, scalar_type, dims, origin,
                     spacing, ghosts, nullptr, strides_samples, INSITU_NODE, Blocks::replace);
}

int insitu_add_block(insitu_instrument* instrument, const char* name, const void* data,
                     int scalar_type, const int64_t dims[3], const double origin[3],
                     const double spacing[3], const int64_t ghosts_low[3],
                     const int64_t ghosts_high[3], const int64_t strides_samples[3],
                     int centering) {
    return add_block("insitu_add_block", instrument, name, data, scalar_type, dims, origin, spacing,
                     ghosts_low, ghosts_high, strides_samples, centering, Blocks::append);
}

int insitu_selects(insitu_instrument* instrument, int64_t step) {
    if (after_failed_startup(instrument)) return INSITU_NOT_SELECTED;
    return guarded("insitu_selects", [&]() -> int {
        require_not_null(instrument, "instrument");
        if (instrument->finalized) {
            throw StateError("insitu_selects(step " + std::to_string(step) +
                             ") after insitu_finalize");
        }
        return instrument->instrument->selects(step) ? INSITU_OK : INSITU_NOT_SELECTED;
    });
}

void insitu_name_next_call(const char* entry_name) {
    try {
        next_call_name = entry_name == nullptr ? std::string() : std::string(entry_name);
    } catch (...) {
        next_call_name.clear();
    }
}

int insitu_execute(insitu_instrument* instrument, int64_t step, double time) {
    if (after_failed_startup(instrument)) return INSITU_NOT_SELECTED;
    return guarded("insitu_execute", [&]() -> int {
        require_not_null(instrument, "instrument");
        // The views are only promised valid until this call returns: forget them whatever
        // happens, so a later execute cannot read memory the simulation has since freed.
        std::map<std::string, std::vector<insitu::Field>> pending;
        pending.swap(instrument->pending_fields);
        if (instrument->finalized) {
            throw StateError("step " + std::to_string(step) + " executed after insitu_finalize");
        }
        std::vector<insitu::Field> fields;
        for (auto& entry : pending) {
            for (insitu::Field& block : entry.second) fields.push_back(std::move(block));
        }
        const insitu::Status status = instrument->instrument->execute(step, time, fields);
        return code_for_status(status, *instrument->instrument, Call::execute);
    });
}

int insitu_finalize(insitu_instrument* instrument) {
    if (after_failed_startup(instrument)) return INSITU_NOT_SELECTED;
    return guarded("insitu_finalize", [&]() -> int {
        require_not_null(instrument, "instrument");
        instrument->pending_fields.clear();
        // A second finalize has nothing left to drain: harmless, so not an error.
        if (instrument->finalized) return INSITU_OK;
        instrument->finalized = true;
        const insitu::Status status = instrument->instrument->finalize();
        return code_for_status(status, *instrument->instrument, Call::finalize);
    });
}

void insitu_destroy(insitu_instrument* instrument) {
    if (instrument == nullptr) return;
    // Finalize explicitly, inside guarded(), so that a failure while draining the writer is
    // recorded for insitu_last_error() instead of being lost in ~Instrument.
    if (!instrument->finalized) insitu_finalize(instrument);
    guarded("insitu_destroy", [&]() -> int {
        delete instrument;
        return INSITU_OK;
    });
}

const char* insitu_last_error(void) {
    return last_error_message.c_str();
}

const char* insitu_status_name(int status) {
    switch (status) {
        case INSITU_OK:
            return "INSITU_OK";
        case INSITU_NOT_SELECTED:
            return "INSITU_NOT_SELECTED";
        case INSITU_DROPPED:
            return "INSITU_DROPPED";
        case INSITU_ERROR_INVALID_ARGUMENT:
            return "INSITU_ERROR_INVALID_ARGUMENT";
        case INSITU_ERROR_PARSE:
            return "INSITU_ERROR_PARSE";
        case INSITU_ERROR_COMPUTE:
            return "INSITU_ERROR_COMPUTE";
        case INSITU_ERROR_IO:
            return "INSITU_ERROR_IO";
        case INSITU_ERROR_STATE:
            return "INSITU_ERROR_STATE";
        case INSITU_ERROR_UNKNOWN:
            return "INSITU_ERROR_UNKNOWN";
        default:
            return "INSITU_UNKNOWN_STATUS";
    }
}

}  // extern "C"
