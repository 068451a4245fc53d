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

/* Centring of a field's samples (insitu::Centering). Node: sample (i, j, k) of the interior lies
 * at origin + (i, j, k) * spacing, so origin is the first interior sample. Cell: sample (i, j, k)
 * is the cell [origin + (i, j, k) * spacing, origin + (i + 1, j + 1, k + 1) * spacing], so origin
 * is the low corner of the first interior cell and the value sits at the cell's centre. */
enum { INSITU_NODE = 0, INSITU_CELL = 1 };

/* Create an instrument from a JSON configuration file or text (see insitu/config.hpp). *out is
 * set to NULL on failure: INSITU_ERROR_PARSE (malformed JSON, or an unknown key while "strict"
 * is true, the default), INSITU_ERROR_INVALID_ARGUMENT (a bad value, named), INSITU_ERROR_IO
 * (unreadable file, archive that cannot be opened), INSITU_ERROR_COMPUTE (no OpenCL device).
 * After a failed start-up (report insitu_last_error() once), every later call given the NULL
 * instrument it left is a silent no-op returning INSITU_NOT_SELECTED, so a run whose
 * visualisation could not start goes on without a message per step. (Before any create failed
 * in the process, a NULL instrument is an error.) */
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

/* The general form: adds one block of a field for the next insitu_execute. Several blocks of one
 * field (the tiles a rank owns) are joined on the grid they share: same spacing and centring,
 * origins a whole number of samples apart, and their interiors together covering a box (a gap,
 * or blocks that disagree, is INSITU_ERROR_INVALID_ARGUMENT naming the blocks). Blocks may share
 * samples (node-centred tiles that share a face); the later block's value is used.
 * ghosts_low, ghosts_high: layers skipped on the low and high side of each axis (NULL = none;
 * ghosts_high NULL = the same as ghosts_low). strides_samples: as insitu_set_field_strided.
 * centering: INSITU_NODE or INSITU_CELL. insitu_set_field(_strided) is this with node centring,
 * after dropping the field's earlier blocks. */
int insitu_add_block(insitu_instrument* instrument, const char* name, const void* data,
                     int scalar_type, const int64_t dims[3], const double origin[3],
                     const double spacing[3], const int64_t ghosts_low[3],
                     const int64_t ghosts_high[3], const int64_t strides_samples[3], int centering);

/* Whether insitu_execute would compute this step: INSITU_OK when the cadence selects it and the
 * archive does not hold it yet, INSITU_NOT_SELECTED otherwise (the cadence skips it, or a
 * restarted run replays a step an earlier run archived), or an error (INSITU_ERROR_STATE after
 * insitu_finalize). Fields need only be set on steps for which it returns INSITU_OK. */
int insitu_selects(insitu_instrument* instrument, int64_t step);

/* For language bindings (the Fortran module): the entry name the next failing call on this
 * thread reports in insitu_last_error() ("insitu_set_field" for the Fortran generic) instead of
 * the C function's. Applies to the next call only. NULL restores the C names. */
void insitu_name_next_call(const char* entry_name);

/* Compute and queue the proxies of the fields set since the last execute, then forget those
 * fields (their pointers are not used again). step: in [0, 2^53 - 1] and increasing; time:
 * simulation time, finite (the archive's JSON manifest holds neither NaN nor Inf).
 * Returns INSITU_OK (queued), INSITU_NOT_SELECTED (the cadence skipped the step, or the archive
 * already holds it from an earlier run: nothing is computed, fields need not be set),
 * INSITU_DROPPED, or an error, after which the run may go on:
 *   INSITU_ERROR_INVALID_ARGUMENT  decreasing or out-of-range step; non-finite time; a
 *                                  configured field not set on a selected step; values beyond
 *                                  float32; blocks of a field that do not join
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
