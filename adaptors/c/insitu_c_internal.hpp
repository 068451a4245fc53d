#pragma once
// For other adaptors' C entry points (adaptors/mpi) built on the C API: how insitu_create_from_file
// and insitu_create_from_json make an instrument. Internal to the project, never installed; the
// function is part of libinsitu (insitu_c.cpp), which exports every symbol it defines.
#include <functional>

#include "insitu.h"
#include "insitu/instrument.hpp"

namespace insitu::c_api {

/// Makes *out as insitu_create_from_file (`is_path`) or insitu_create_from_json do: the same
/// checks (out, then `argument`, reported as `argument_name`), status codes, insitu_last_error()
/// message under the name `entry`, and silent no-ops on the NULL handle after a failure.
/// `add_options`, when set, adjusts the options first (a communicator, say); it runs inside the
/// guard, so what it throws becomes a status code and counts as a failed start-up. Never throws.
int create_with_options(const char* entry, const char* argument_name, const char* argument,
                        bool is_path,
                        const std::function<void(insitu::InstrumentOptions&)>& add_options,
                        insitu_instrument** out);

}  // namespace insitu::c_api
