/* heat_c_mpi: heat_c's simulation on MPI ranks, cell-centred, with two ghost layers, through
 * the C API of insitu_mpi.h.
 *
 *   mpiexec -n RANKS heat_c_mpi ARCHIVE [STEPS] [--stale-halos]
 *
 * Heat diffuses from three hot spots held at temperature 1 through a unit cube of 32^3 cells
 * (the values at the cells' centres, as finite-volume codes keep them), cut into slabs along z:
 * rank r owns a contiguous range of z planes of cells (32 / RANKS of them, the first 32 mod
 * RANKS ranks one more; at most 16 ranks) and holds two ghost layers on every side, as codes
 * with a wider stencil do. The x and y ghosts, and the z ghosts of the first and last slab, are the
 * cold walls (0); the other z ghosts are the neighbours' planes, exchanged after every update,
 * before the step is handed to libinsitu (the halo rule: libinsitu renders the cells between two
 * ranks' blocks from the lower rank's high ghost layer, so it must hold the neighbour's current
 * values).
 *
 * --stale-halos breaks the rule on purpose: the halos are exchanged before the update instead
 * of after it, so the array handed over holds older ghosts than its neighbours' interiors, and
 * libinsitu's halo check warns at the first step stored, naming the ranks and the side.
 *
 * Every rank hands its slab to the distributed instrument with insitu_add_block(...,
 * INSITU_CELL): origin is the low corner of its first interior cell. Rank 0 writes the archive.
 * Exits 0 when every call succeeded on every rank, 1 when any failed (the run still goes to the
 * end), 2 for bad arguments.
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "insitu_mpi.h"

enum {
    kCells = 32,                 /* cells per axis, whole domain */
    kGhosts = 2,                 /* ghost layers on each side */
    kRow = kCells + 2 * kGhosts, /* allocated cells along x and y */
    kPlane = kRow * kRow         /* cells of one x-y plane, ghosts included */
};

/* Hot spots, in global cell coordinates, with their radius in cells. */
static const double kSpots[3][4] = {
    {9.0, 10.0, 12.0, 3.0}, {22.0, 20.0, 16.0, 4.0}, {14.0, 24.0, 23.0, 2.5}};

/* Cell (i, j, k) of the slab, ghosts included (i, j, k from 0 at the first ghost), x fastest. */
static size_t index_of(int i, int j, int k) {
    return (size_t)i + (size_t)kRow * ((size_t)j + (size_t)kRow * (size_t)k);
}

/* Holds the hot spots at temperature 1 on this rank's planes (global plane z_first onwards). */
static void apply_sources(double* t, int nz_local, int z_first) {
    for (int k = 0; k < nz_local; ++k) {
        for (int j = 0; j < kCells; ++j) {
            for (int i = 0; i < kCells; ++i) {
                for (int s = 0; s < 3; ++s) {
                    const double dx = i - kSpots[s][0], dy = j - kSpots[s][1],
                                 dz = z_first + k - kSpots[s][2];
                    if (dx * dx + dy * dy + dz * dz <= kSpots[s][3] * kSpots[s][3]) {
                        t[index_of(i + kGhosts, j + kGhosts, k + kGhosts)] = 1.0;
                    }
                }
            }
        }
    }
}

/* One explicit Euler step with the 7-point stencil on the interior; ghosts are only read. */
static void diffuse(const double* current, double* next, int nz_local, double diffusion_number) {
    const size_t sy = kRow, sz = kPlane;
    for (int k = kGhosts; k < kGhosts + nz_local; ++k) {
        for (int j = kGhosts; j < kGhosts + kCells; ++j) {
            for (int i = kGhosts; i < kGhosts + kCells; ++i) {
                const size_t c = index_of(i, j, k);
                const double laplacian = current[c - 1] + current[c + 1] + current[c - sy] +
                                         current[c + sy] + current[c - sz] + current[c + sz] -
                                         6.0 * current[c];
                next[c] = current[c] + diffusion_number * laplacian;
            }
        }
    }
}

/* The halo exchange: the top kGhosts interior planes up into the upper neighbour's low ghosts,
 * the bottom ones down into the lower neighbour's high ghosts (MPI_PROC_NULL at the walls leaves
 * the walls' zeros). Whole x-y planes are contiguous, so they go without packing. */
static void exchange_halos(double* t, int nz_local, int below, int above) {
    const int count = kGhosts * kPlane;
    MPI_Sendrecv(t + index_of(0, 0, nz_local), count, MPI_DOUBLE, above, 0, t, count, MPI_DOUBLE,
                 below, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    MPI_Sendrecv(t + index_of(0, 0, kGhosts), count, MPI_DOUBLE, below, 1,
                 t + index_of(0, 0, kGhosts + nz_local), count, MPI_DOUBLE, above, 1,
                 MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

/* Copies `text` into `out` with JSON's string escapes for '"' and '\'; 0 if it does not fit. */
static int json_escape(const char* text, char* out, size_t capacity) {
    size_t used = 0;
    for (; *text != '\0'; ++text) {
        const int escaped = (*text == '"' || *text == '\\');
        if (used + (size_t)escaped + 2 > capacity) return 0;
        if (escaped) out[used++] = '\\';
        out[used++] = *text;
    }
    out[used] = '\0';
    return 1;
}

/* heat_c's configuration (two 32x32 views, every 10th step) into `archive`; 0 if too long. */
static int make_config(const char* archive, char* config, size_t capacity) {
    char escaped[4096];
    if (!json_escape(archive, escaped, sizeof escaped)) return 0;
    const int written = snprintf(
        config, capacity,
        "{\"fields\": [\"temperature\"],\n"
        " \"views\": [{\"azimuth\": 30, \"elevation\": 20, \"size\": [32, 32]},\n"
        "           {\"azimuth\": 120, \"elevation\": -10, \"camera\": \"perspective\",\n"
        "            \"fov\": 30, \"size\": [32, 32]}],\n"
        " \"transfer_function\": {\"points\": [[0.0, 0, 0, 1, 0], [0.3, 0, 1, 0, 0.2],\n"
        "                                     [1.0, 1, 0, 0, 0.8]], \"unit_length\": 0.1},\n"
        " \"every\": 10, \"archive\": \"%s\",\n"
        " \"writer\": {\"queue\": 2, \"when_full\": \"block\"}}\n",
        escaped);
    return written > 0 && (size_t)written < capacity;
}

/* Runs the simulation on this rank's slab; returns the number of failed calls. */
static int run(insitu_instrument* instrument, int steps, int stale_halos, int rank, int ranks) {
    int nz_local = kCells / ranks;
    const int z_first = rank * nz_local + (rank < kCells % ranks ? rank : kCells % ranks);
    if (rank < kCells % ranks) ++nz_local;
    const int below = rank == 0 ? MPI_PROC_NULL : rank - 1;
    const int above = rank == ranks - 1 ? MPI_PROC_NULL : rank + 1;

    const size_t cells = (size_t)kPlane * (size_t)(nz_local + 2 * kGhosts);
    double* current = calloc(cells, sizeof *current);
    double* next = calloc(cells, sizeof *next);
    if (current == NULL || next == NULL) {
        fprintf(stderr, "heat_c_mpi: rank %d: out of memory\n", rank);
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    const double h = 1.0 / kCells;
    const double diffusion_number = 0.15; /* alpha dt / dx^2, below the 1/6 limit */
    const double dt = diffusion_number * h * h;
    const int64_t dims[3] = {kRow, kRow, nz_local + 2 * kGhosts};
    const int64_t ghosts[3] = {kGhosts, kGhosts, kGhosts};
    const double origin[3] = {0.0, 0.0, z_first * h}; /* low corner of the first interior cell */
    const double spacing[3] = {h, h, h};

    int failures = 0;
    apply_sources(current, nz_local, z_first);
    exchange_halos(current, nz_local, below, above);
    for (int step = 1; step <= steps; ++step) {
        if (stale_halos) exchange_halos(current, nz_local, below, above);
        diffuse(current, next, nz_local, diffusion_number);
        apply_sources(next, nz_local, z_first);
        double* swap = current;
        current = next;
        next = swap;
        /* After the update, before the hand-over: the halo rule. (--stale-halos exchanges before
         * the stencil instead, where it reads them: the simulation is the same, but the array
         * handed over keeps the ghosts of two steps before.) */
        if (!stale_halos) exchange_halos(current, nz_local, below, above);

        int status = INSITU_OK;
        if (insitu_selects(instrument, step) == INSITU_OK) {
            status = insitu_add_block(instrument, "temperature", current, INSITU_FLOAT64, dims,
                                      origin, spacing, ghosts, ghosts, NULL, INSITU_CELL);
        }
        /* Collective: every rank calls it every step, even when its own hand-over failed. */
        const int executed = insitu_execute(instrument, step, step * dt);
        if (status == INSITU_OK) status = executed;
        if (status < 0) {
            fprintf(stderr, "heat_c_mpi: rank %d: step %d: %s: %s\n", rank, step,
                    insitu_status_name(status), insitu_last_error());
            ++failures;
        } else if (status == INSITU_OK && rank == 0) {
            printf("step %d: stored\n", step);
        }
    }
    free(current);
    free(next);
    return failures;
}

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    const int stale_halos = argc > 2 && strcmp(argv[argc - 1], "--stale-halos") == 0;
    const int counted = argc - stale_halos;
    const int steps = counted == 3 ? atoi(argv[2]) : 40;
    static char config[8192];
    int usage = 0;
    if (counted < 2 || counted > 3 || steps < 1 || ranks > kCells / kGhosts) {
        usage = 1;
    } else if (!make_config(argv[1], config, sizeof config)) {
        usage = 1;
    }
    if (usage) {
        if (rank == 0) {
            /* At most one rank per kGhosts planes: a halo is a neighbour's interior planes. */
            fprintf(stderr,
                    "usage: heat_c_mpi ARCHIVE [STEPS] [--stale-halos] (STEPS > 0, at most %d "
                    "ranks)\n",
                    kCells / kGhosts);
        }
        MPI_Finalize();
        return 2;
    }

    insitu_instrument* instrument = NULL;
    const int created = insitu_create_mpi_from_json(config, MPI_COMM_WORLD, &instrument);
    if (created != INSITU_OK) {
        /* Start-up fails alike on every rank (a bad configuration, no device). */
        if (rank == 0) {
            fprintf(stderr, "heat_c_mpi: %s: %s\n", insitu_status_name(created),
                    insitu_last_error());
        }
        MPI_Finalize();
        return 1;
    }
    int failures = run(instrument, steps, stale_halos, rank, ranks);
    const int finalized = insitu_finalize(instrument);
    if (finalized != INSITU_OK) {
        fprintf(stderr, "heat_c_mpi: rank %d: finalize: %s: %s\n", rank,
                insitu_status_name(finalized), insitu_last_error());
        ++failures;
    }
    insitu_destroy(instrument); /* before MPI_Finalize: it frees libinsitu's communicator */
    int any_failures = 0;
    MPI_Allreduce(&failures, &any_failures, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (rank == 0) {
        printf("heat_c_mpi: %d ranks, %d steps into %s, %d failures (most on one rank)\n", ranks,
               steps, argv[1], any_failures);
    }
    MPI_Finalize();
    return any_failures == 0 ? 0 : 1;
}
