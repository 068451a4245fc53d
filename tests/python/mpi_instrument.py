"""insitu.Instrument(config, comm=MPI.COMM_WORLD) under mpiexec (tests/python/CMakeLists.txt):
each rank hands over its slab of a field (z split, one ghost layer at the cut), then rank 0
writes the same steps from the whole field in one process and holds the two archives to each
other: every proxy of every step and view within the tolerances of the C++ test
(tests/mpi/instrument_mpi_test.cpp: depths 1e-4, the rest 1e-5). Exits non-zero otherwise.

usage: mpiexec -n N python3 mpi_instrument.py DIRECTORY"""
import os
import sys

import numpy as np
from mpi4py import MPI

import insitu

DIMS = (30, 27, 24)
SPACING = (0.5, 0.5, 0.25)
ORIGIN = (-3.0, 1.0, 2.0)


def field_at(step):
    """Two blobs and a ramp along x, indexed [x, y, z]; changes with the step."""
    x, y, z = np.meshgrid(*[np.linspace(-1.0, 1.0, n) for n in DIMS], indexing="ij")
    blobs = np.exp(-((x - 0.3) ** 2 + 2.0 * (y + 0.2) ** 2 + (z - 0.1) ** 2) * 6.0) + \
        0.7 * np.exp(-((x + 0.4) ** 2 + (y - 0.3) ** 2 + 3.0 * (z + 0.35) ** 2) * 8.0)
    return (blobs * (1.0 + 0.2 * step) + 0.05 * (x + 1.0)).astype(np.float32)


def config(archive):
    return {"archive": archive, "fields": ["f"], "on_existing": "replace", "every": 1,
            "volume": False, "precision": "float",
            "views": [{"azimuth": 30, "elevation": 20, "camera": "perspective",
                       "size": [48, 40]},
                      {"azimuth": 200, "elevation": -35, "size": [40, 40]}],
            "proxies": ["depth", "attenuation", "optical_depth"],
            "transfer_function": {"points": [[0.0, 0.1, 0.2, 0.9, 0.0],
                                             [0.4, 0.9, 0.6, 0.1, 0.3],
                                             [1.5, 1.0, 1.0, 1.0, 0.9]]}}


def my_slab(field, rank, size):
    """This rank's interior z range [low, high) and the Field with a ghost layer at each cut."""
    cuts = np.linspace(0, DIMS[2], size + 1).astype(int)
    low, high = cuts[rank], cuts[rank + 1]
    ghost_low = 1 if rank > 0 else 0
    ghost_high = 1 if rank < size - 1 else 0
    block = field[:, :, low - ghost_low:high + ghost_high]   # a strided view, not a copy
    origin = (ORIGIN[0], ORIGIN[1], ORIGIN[2] + low * SPACING[2])
    return insitu.Field(block, ghost_layers=((0, 0, ghost_low), (0, 0, ghost_high)),
                        spacing=SPACING, origin=origin)


def compare(reference, distributed):
    """Failures (text), and how many arrays were compared."""
    one, ranks = insitu.open(reference), insitu.open(distributed)
    failures, compared = [], 0
    if one.steps != ranks.steps:
        return [f"steps {ranks.steps}, one process {one.steps}"], 0
    for step in one.steps:
        for view in range(len(one.views)):
            a, b = one.proxies(step, view), ranks.proxies(step, view)
            if sorted(a.keys()) != sorted(b.keys()):
                failures.append(f"step {step} view {view}: proxies {b.keys()} vs {a.keys()}")
                continue
            for name in a.keys():
                # Depths are world distances, the rest transmittances and optical depths.
                tolerance = 1e-4 if name in ("depth", "mean_depth") else 1e-5
                x, y = np.asarray(a[name]), np.asarray(b[name])
                compared += 1
                if x.shape != y.shape or not np.allclose(x, y, rtol=0, atol=tolerance):
                    with np.errstate(invalid="ignore"):
                        error = np.nanmax(np.abs(np.where(np.isinf(x) & (x == y), 0, x - y)))
                    failures.append(f"step {step} view {view} {name}: max error {error}")
    return failures, compared


def main():
    world = MPI.COMM_WORLD
    directory = world.bcast(sys.argv[1] if world.rank == 0 else None, root=0)
    if world.rank == 0:
        os.makedirs(directory, exist_ok=True)
    world.Barrier()
    distributed = os.path.join(directory, "ranks.cdb")
    reference = os.path.join(directory, "one.cdb")
    instrument = insitu.Instrument(config(distributed), comm=world, raise_errors=True, log=False)
    for step in range(3):
        instrument.execute(step, 0.5 * step, {"f": my_slab(field_at(step), world.rank,
                                                           world.size)})
    instrument.finalize()
    composite_seconds = instrument.statistics["composite_seconds"]
    del instrument          # frees the communicator's duplicate before MPI_Finalize
    failures = []
    if world.size > 1 and composite_seconds <= 0.0:
        failures.append(f"rank {world.rank}: no compositing time at {world.size} ranks")
    if world.rank == 0:
        with insitu.Instrument(config(reference), raise_errors=True, log=False) as one:
            for step in range(3):
                one.execute(step, 0.5 * step, {"f": field_at(step)}, spacing=SPACING,
                            origin=ORIGIN)
        found, compared = compare(reference, distributed)
        failures += found
        names = insitu.open(reference).proxies(0).keys()
        if not {"attenuation", "depth"} <= set(names) or compared != 3 * 2 * len(names):
            failures.append(f"{compared} proxies compared ({names}), expected 3 steps x 2 "
                            "views of each")
        print(f"mpi_instrument: {world.size} ranks, {compared} proxies against one process: "
              f"{'same' if not failures else 'DIFFERENT'}")
    failures = sum(world.allgather(failures), [])
    for failure in failures if world.rank == 0 else []:
        print("mpi_instrument:", failure, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
