#!/usr/bin/env python3
"""The Python module's costs (issue 44), printed, never asserted:
  1. Instrument.execute from Python against the same C++ call (bench_python_baseline): ms per
     call, best of N and spread, and their ratio;
  2. peak memory gained over execute for a C-contiguous 256^3 float64 field, from Python and
     from C++ (a copy of the field would add its 128 MB to Python's);
  3. insitu.open of an archive of many steps (written here by a tiny instrumented run);
  4. reading one step's proxies at 256^2 (Archive.proxies).
Each measurement runs in a fresh process so that peak memory is its own.

  PYTHONPATH=build/python python3 bench/bench_python.py --baseline build/bench/bench_python_baseline
      [--size 256] [--image 256] [--repeats 5] [--steps 10000] [--work DIR]
"""
import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def cpu_model():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor()


def blob(n):
    """bench_python_baseline.cpp's field, indexed [x, y, z], x fastest: a C-contiguous
    (z, y, x) array handed over as its transpose (a view). Made plane by plane so that no
    temporary raises the peak memory the benchmark measures."""
    import numpy as np
    axis = np.linspace(-1.0, 1.0, n)
    zyx = np.empty((n, n, n))
    y, x = np.meshgrid(axis + 0.2, axis - 0.3, indexing="ij")
    for k in range(n):
        zyx[k] = np.exp(-(x * x + 2.0 * y * y + 0.5 * axis[k] ** 2) * 3.0)
    return zyx.transpose()


def python_execute(size, image, repeats, archive):
    """The Python side of 1 and 2, run in its own process; prints one JSON line."""
    import insitu
    instrument = insitu.Instrument({"fields": ["v"], "views": [{"size": [image, image]}],
                                    "every": 1, "volume": False, "on_existing": "replace",
                                    "archive": archive}, raise_errors=True, log=False)
    field = blob(size)
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    ms = []
    inside_ms = []  # the C++ Instrument::execute's own time within each call
    for r in range(repeats + 1):  # call 0 builds the kernels: left out
        before = instrument.statistics["execute_seconds"]
        start = time.perf_counter()
        instrument.execute(r, float(r), {"v": field})
        if r > 0:
            ms.append((time.perf_counter() - start) * 1e3)
            inside_ms.append((instrument.statistics["execute_seconds"] - before) * 1e3)
    inside = instrument.statistics["execute_seconds"]
    instrument.finalize()
    print(json.dumps({"ms": ms, "inside_ms": inside_ms, "rss_before_mb": rss_before,
                      "inside_s": inside,
                      "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0}))


def run_json(command):
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def spread(values):
    return f"best {min(values):.1f} ms, median {statistics.median(values):.1f}, " \
           f"max {max(values):.1f} (n = {len(values)})"


def write_many_steps(archive, steps):
    import insitu
    import numpy as np
    field = blob(8)
    with insitu.Instrument({"fields": ["v"], "views": [{"size": [8, 8]}], "every": 1,
                            "volume": False, "proxies": ["depth"], "on_existing": "replace",
                            "archive": archive}, raise_errors=True, log=False) as instrument:
        for step in range(steps):
            instrument.execute(step, float(step), {"v": field})


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", required=True, help="bench_python_baseline")
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--image", type=int, default=256)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=10000)
    parser.add_argument("--work", default=None)
    parser.add_argument("--python-side", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="bench_python_")
    if args.python_side:
        python_execute(args.size, args.image, args.repeats, os.path.join(work, "py.cdb"))
        return
    import insitu
    print(f"bench_python: {cpu_model()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    common = ["--size", str(args.size), "--image", str(args.image), "--repeats", str(args.repeats)]
    cpp = run_json([args.baseline, *common, "--archive", os.path.join(work, "cpp.cdb")])
    py = run_json([sys.executable, __file__, "--python-side", "--baseline", args.baseline,
                   "--work", work, *common])
    print(f"execute {args.size}^3 float64, {args.image}^2 view:")
    print(f"  C++ call     {spread(cpp['ms'])}")
    print(f"  from Python  {spread(py['ms'])}")
    print(f"  ratio        best {min(py['ms']) / min(cpp['ms']):.3f}, "
          f"median {statistics.median(py['ms']) / statistics.median(cpp['ms']):.3f}")
    # The same call in the same process: the Python call's wall time against the C++ execute's
    # own time inside it. What the binding adds (the arrays viewed, the GIL released), free of
    # the run-to-run noise of comparing two processes on a shared machine.
    per_call = [outside / inside for outside, inside in zip(py["ms"], py["inside_ms"])]
    added = statistics.median(a - b for a, b in zip(py["ms"], py["inside_ms"]))
    print(f"  same call    Python / C++ execute inside it: best {min(per_call):.4f}, "
          f"median {statistics.median(per_call):.4f}, max {max(per_call):.4f} "
          f"(the binding adds {added:.2f} ms a call, median)")
    field_mb = args.size ** 3 * 8 / 2 ** 20
    print(f"peak memory gained over execute (the field is {field_mb:.0f} MB):")
    print(f"  C++ call     {cpp['peak_rss_mb'] - cpp['rss_before_mb']:.1f} MB "
          f"(peak {cpp['peak_rss_mb']:.0f} MB)")
    print(f"  from Python  {py['peak_rss_mb'] - py['rss_before_mb']:.1f} MB "
          f"(peak {py['peak_rss_mb']:.0f} MB)")

    many = os.path.join(work, "many.cdb")
    start = time.perf_counter()
    write_many_steps(many, args.steps)
    print(f"archive of {args.steps} steps written in {time.perf_counter() - start:.1f} s")
    opens = []
    for _ in range(5):
        start = time.perf_counter()
        archive = insitu.open(many)
        count, times = len(archive.steps), archive.times
        opens.append((time.perf_counter() - start) * 1e3)
    assert count == args.steps and len(times) == count
    print(f"insitu.open + steps + times, {count} steps: {spread(opens)}")

    archive = insitu.open(os.path.join(work, "py.cdb"))
    step = archive.steps[-1]
    reads = []
    for _ in range(10):
        start = time.perf_counter()
        proxies = archive.proxies(step)
        arrays = [proxies[name] for name in proxies.keys()]
        reads.append((time.perf_counter() - start) * 1e3)
    shape = arrays[0].shape
    print(f"one step's proxies at {shape[1]}x{shape[0]} ({', '.join(proxies.keys())}): "
          f"{spread(reads)}")


if __name__ == "__main__":
    main()
