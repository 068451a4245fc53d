/* heat_c: a small C simulation instrumented through the libinsitu C API (insitu.h).
 *
 *   heat_c ARCHIVE [STEPS]
 *
 * Heat diffuses from three hot spots held at temperature 1 through a unit cube of 32^3 samples,
 * with one ghost layer on every side held at 0 (cold walls). Every step hands the current array
 * to libinsitu; the configuration selects every 10th step, whose proxies go to ARCHIVE.
 * Exits 0 when every call succeeded, 1 when any failed (the run still goes to the end, as a real
 * simulation would), 2 for bad arguments.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "insitu.h"

enum {
    kInterior = 32,                      /* samples per axis inside the walls */
    kGhosts = 1,                         /* ghost layers on each side */
    kAllocated = kInterior + 2 * kGhosts /* samples per axis in memory */
};

/* x fastest, as libinsitu expects. */
static size_t index_of(int i, int j, int k) {
    return (size_t)i + (size_t)kAllocated * ((size_t)j + (size_t)kAllocated * (size_t)k);
}

/* Hot spots, in interior sample coordinates, with their radius in samples. */
static const double kSpots[3][4] = {
    {9.0, 10.0, 12.0, 3.0}, {22.0, 20.0, 16.0, 4.0}, {14.0, 24.0, 23.0, 2.5}};

/* Holds the hot spots at temperature 1: heat sources keep the field from fading to nothing. */
static void apply_sources(double* temperature) {
    for (int k = 0; k < kInterior; ++k) {
        for (int j = 0; j < kInterior; ++j) {
            for (int i = 0; i < kInterior; ++i) {
                for (int s = 0; s < 3; ++s) {
                    const double dx = i - kSpots[s][0], dy = j - kSpots[s][1],
                                 dz = k - kSpots[s][2];
                    if (dx * dx + dy * dy + dz * dz <= kSpots[s][3] * kSpots[s][3]) {
                        temperature[index_of(i + kGhosts, j + kGhosts, k + kGhosts)] = 1.0;
                    }
                }
            }
        }
    }
}

/* One explicit Euler step of dT/dt = alpha * laplacian(T) with the 7-point stencil.
 * diffusion_number = alpha * dt / dx^2 must stay <= 1/6 for stability in 3D. Ghosts are not
 * written, so they keep the walls' temperature 0. */
static void diffuse(const double* current, double* next, double diffusion_number) {
    const size_t sx = 1, sy = kAllocated, sz = (size_t)kAllocated * kAllocated;
    for (int k = kGhosts; k < kGhosts + kInterior; ++k) {
        for (int j = kGhosts; j < kGhosts + kInterior; ++j) {
            for (int i = kGhosts; i < kGhosts + kInterior; ++i) {
                const size_t c = index_of(i, j, k);
                const double laplacian = current[c - sx] + current[c + sx] + current[c - sy] +
                                         current[c + sy] + current[c - sz] + current[c + sz] -
                                         6.0 * current[c];
                next[c] = current[c] + diffusion_number * laplacian;
            }
        }
    }
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

int main(int argc, char** argv) {
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: heat_c ARCHIVE [STEPS]\n");
        return 2;
    }
    const int steps = argc == 3 ? atoi(argv[2]) : 40;
    if (steps < 1) {
        fprintf(stderr, "heat_c: STEPS = %s is not a positive integer\n", argv[2]);
        return 2;
    }
    char archive[4096];
    if (!json_escape(argv[1], archive, sizeof archive)) {
        fprintf(stderr, "heat_c: ARCHIVE path is too long\n");
        return 2;
    }

    /* Two small views, so the example runs in seconds on a CPU OpenCL device. The transfer
     * function covers the field's range [0, 1]; unit_length is in world units (the cube is 1
     * wide), so opacity builds up over a fraction of the cube. */
    char config[8192];
    snprintf(config, sizeof config,
             "{\"fields\": [\"temperature\"],\n"
             " \"views\": [{\"azimuth\": 30, \"elevation\": 20, \"size\": [32, 32]},\n"
             "           {\"azimuth\": 120, \"elevation\": -10, \"camera\": \"perspective\",\n"
             "            \"fov\": 30, \"size\": [32, 32]}],\n"
             " \"transfer_function\": {\"points\": [[0.0, 0, 0, 1, 0], [0.3, 0, 1, 0, 0.2],\n"
             "                                     [1.0, 1, 0, 0, 0.8]], \"unit_length\": 0.1},\n"
             " \"layers\": \"auto\", \"intervals\": {\"count\": 8, \"mode\": \"uniform\"},\n"
             " \"every\": 10, \"archive\": \"%s\",\n"
             " \"writer\": {\"queue\": 2, \"when_full\": \"block\"}}\n",
             archive);

    insitu_instrument* instrument = NULL;
    const int created = insitu_create_from_json(config, &instrument);
    if (created != INSITU_OK) {
        /* A bad configuration is found at start-up; the simulation decides what to do. */
        fprintf(stderr, "heat_c: %s: %s\n", insitu_status_name(created), insitu_last_error());
        return 1;
    }

    const size_t samples = (size_t)kAllocated * kAllocated * kAllocated;
    double* current = calloc(samples, sizeof *current);
    double* next = calloc(samples, sizeof *next);
    if (current == NULL || next == NULL) {
        fprintf(stderr, "heat_c: out of memory\n");
        free(current);
        free(next);
        insitu_destroy(instrument);
        return 1;
    }

    const double spacing_world = 1.0 / kInterior;
    const double diffusion_number = 0.15; /* alpha dt / dx^2, below the 1/6 limit */
    const double alpha = 1.0;             /* diffusivity, world units^2 per unit time */
    const double dt = diffusion_number * spacing_world * spacing_world / alpha;
    const int64_t dims[3] = {kAllocated, kAllocated, kAllocated};
    const int64_t ghosts[3] = {kGhosts, kGhosts, kGhosts};
    const double origin[3] = {0.0, 0.0, 0.0};
    const double spacing[3] = {spacing_world, spacing_world, spacing_world};

    int failures = 0, stored = 0;
    apply_sources(current);
    for (int step = 1; step <= steps; ++step) {
        diffuse(current, next, diffusion_number);
        apply_sources(next);
        double* swap = current;
        current = next;
        next = swap;

        /* The array moves every step (double buffering), so it is handed over every step. */
        int status = insitu_set_field(instrument, "temperature", current, INSITU_FLOAT64, dims,
                                      origin, spacing, ghosts);
        if (status == INSITU_OK) status = insitu_execute(instrument, step, step * dt);
        if (status < 0) {
            /* Report and go on: the simulation is worth more than its pictures. */
            fprintf(stderr, "heat_c: step %d: %s: %s\n", step, insitu_status_name(status),
                    insitu_last_error());
            ++failures;
        } else if (status != INSITU_NOT_SELECTED) {
            printf("step %d: %s\n", step, insitu_status_name(status));
            stored += status == INSITU_OK;
        }
    }

    const int status = insitu_finalize(instrument);
    if (status != INSITU_OK) {
        fprintf(stderr, "heat_c: finalize: %s: %s\n", insitu_status_name(status),
                insitu_last_error());
        ++failures;
    }
    insitu_destroy(instrument);
    free(current);
    free(next);
    printf("heat_c: %d steps, %d stored in %s, %d failures\n", steps, stored, argv[1], failures);
    return failures == 0 ? 0 : 1;
}
