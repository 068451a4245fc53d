/* libinsitu C API: instrument a C (or, through insitu.f90, Fortran) simulation.
 *
 * Exception-free: every function returns a status code; insitu_last_error() gives the message of
 * the most recent failure on the calling thread. Nothing here terminates the simulation.
 * One instrument is driven from one thread at a time; separate instruments are independent.
 *
 *   insitu_instrument* in = NULL;
 *   if (insitu_create_from_file("insitu.json", &in) != INSITU_OK) puts(insitu_last_error());
 *   for (step...) {
 *       insitu_set_field(in, "v", v, INSITU_FLOAT64, dims, origin, spacing, ghosts);
 *       insitu_execute(in, step, time);
 *   }
 *   insitu_finalize(in);
 *   insitu_destroy(in);
 */
#ifndef INSITU_H
#define INSITU_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct insitu_instrument insitu_instrument;

/* Status codes. */
enum {
    INSITU_OK = 0,
    INSITU_NOT_SELECTED = 1,            /* the cadence skipped this step: not an error */
    INSITU_DROPPED = 2,                 /* writer queue full, when_full = "drop": step not stored */
    INSITU_ERROR_INVALID_ARGUMENT = -1, /* null pointer, bad dims/type/config value */
    INSITU_ERROR_PARSE = -2,            /* malformed configuration */
    INSITU_ERROR_COMPUTE = -3,          /* OpenCL: no platform, build or launch failure */
    INSITU_ERROR_IO = -4,               /* archive cannot be written or read */
    INSITU_ERROR_STATE = -5,            /* e.g. execute after finalize */
    INSITU_ERROR_UNKNOWN = -99
};

/* Scalar types of field data (insitu::ScalarType). */
enum {
    INSITU_UINT8 = 0,
    INSITU_UINT16 = 1,
    INSITU_INT16 = 2,
    INSITU_FLOAT32 = 3,
    INSITU_FLOAT64 = 4
};

/* Create an instrument from a JSON configuration file or text (see insitu/config.hpp). *out is
 * set to NULL on failure: INSITU_ERROR_PARSE (malformed JSON), INSITU_ERROR_INVALID_ARGUMENT (a
 * bad value, named), INSITU_ERROR_IO (unreadable file, archive that cannot be opened),
 * INSITU_ERROR_COMPUTE (no OpenCL device). Unknown keys are logged to stderr, not errors. */
int insitu_create_from_file(const char* path, insitu_instrument** out);
int insitu_create_from_json(const char* json_text, insitu_instrument** out);

/* Hand over (zero-copy) the current array of a field for the next insitu_execute.
 * name: one of the configuration's "fields" (else INSITU_ERROR_INVALID_ARGUMENT naming it);
 * setting it again before execute replaces it. scalar_type: INSITU_UINT8 ... INSITU_FLOAT64.
 * dims: allocated samples per axis including ghosts (x fastest, so a Fortran a(nx, ny, nz) is
 * {nx, ny, nz}); ghosts: layers skipped on each side of each axis (may be NULL = none);
 * origin (of the first interior sample), spacing: world units (may be NULL = 0 and 1).
 * The pointer must stay valid until insitu_execute returns. */
int insitu_set_field(insitu_instrument* instrument, const char* name, const void* data,
                     int scalar_type, const int64_t dims[3], const double origin[3],
                     const double spacing[3], const int64_t ghosts[3]);

/* insitu_set_field for arrays that are padded, transposed or interleaved: strides_samples gives
 * the distance between neighbours along x, y, z in samples (not bytes), all > 0. NULL strides =
 * x-fastest contiguous, {1, dims[0], dims[0] * dims[1]}. The Fortran module uses it for array
 * sections that are not contiguous. */
int insitu_set_field_strided(insitu_instrument* instrument, const char* name, const void* data,
                             int scalar_type, const int64_t dims[3], const double origin[3],
                             const double spacing[3], const int64_t ghosts[3],
                             const int64_t strides_samples[3]);

/* Compute and queue the proxies of the fields set since the last execute, then forget those
 * fields (their pointers are not used again). step: in [0, 2^53 - 1] and increasing; time:
 * simulation time, finite (the archive's JSON manifest holds neither NaN nor Inf).
 * Returns INSITU_OK (queued), INSITU_NOT_SELECTED (the cadence skipped the step; nothing is
 * computed), INSITU_DROPPED, or an error, after which the run may go on:
 *   INSITU_ERROR_INVALID_ARGUMENT  duplicate, decreasing or out-of-range step; non-finite
 *                                  time; the first configured field not set (on steps the
 *                                  cadence skips too); values beyond float32
 *   INSITU_ERROR_COMPUTE           OpenCL failure while computing the proxies
 *   INSITU_ERROR_STATE             called after insitu_finalize
 * A step the writer thread fails to store is reported by insitu_finalize. */
int insitu_execute(insitu_instrument* instrument, int64_t step, double time);

/* Drain the writer and stop it; later sets and executes fail with INSITU_ERROR_STATE. Returns
 * INSITU_ERROR_IO when any step could not be written (the archive still names only complete
 * steps). A second call returns INSITU_OK. */
int insitu_finalize(insitu_instrument* instrument);

/* Free the instrument (finalizes first if needed; a failure of that finalize is left in
 * insitu_last_error()). NULL is fine. */
void insitu_destroy(insitu_instrument* instrument);

/* Message of the most recent failure on this thread ("" if none). Successful calls leave it as
 * it was. Valid until the next failing call on this thread. */
const char* insitu_last_error(void);

/* Name of a status code ("INSITU_OK", "INSITU_NOT_SELECTED", ...); "INSITU_UNKNOWN_STATUS" for a
 * value that is none of them. The string is static. */
const char* insitu_status_name(int status);

#ifdef __cplusplus
}
#endif

#endif /* INSITU_H */
