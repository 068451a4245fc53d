#!/usr/bin/env python3
"""libinsitu from Python, end to end: a small numpy simulation (3-D heat diffusion of two hot
blobs) instrumented with insitu.Instrument, then its archive explored: a timestep strip, an
orbit and an opacity edit, drawn with matplotlib into one PNG.

  PYTHONPATH=build/python python3 examples/python/explore_and_simulate.py OUT_DIR
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import insitu  # noqa: E402


def simulate(archive, n=32, steps=40, every=10):
    """Explicit heat diffusion on an n^3 grid with one ghost layer (fixed at 0) per side."""
    u = np.zeros((n + 2, n + 2, n + 2))  # indexed [x, y, z], ghosts included
    x, y, z = np.meshgrid(*[np.linspace(-1, 1, n)] * 3, indexing="ij")
    u[1:-1, 1:-1, 1:-1] = (np.exp(-((x - 0.4) ** 2 + y ** 2 + z ** 2) * 20)
                           + np.exp(-((x + 0.4) ** 2 + (y - 0.3) ** 2 + z ** 2) * 30))
    config = {"fields": ["temperature"], "every": every, "archive": archive,
              "views": [{"azimuth": 30, "elevation": 20, "size": [128, 128]}],
              "on_existing": "replace"}
    with insitu.Instrument(config) as instrument:
        for step in range(1, steps + 1):
            inner = u[1:-1, 1:-1, 1:-1]
            laplacian = (u[2:, 1:-1, 1:-1] + u[:-2, 1:-1, 1:-1] + u[1:-1, 2:, 1:-1]
                         + u[1:-1, :-2, 1:-1] + u[1:-1, 1:-1, 2:] + u[1:-1, 1:-1, :-2]
                         - 6 * inner)
            inner += 0.1 * laplacian
            if instrument.selects(step):  # the whole array, ghosts skipped: nothing copied
                status = instrument.execute(step, step * 0.1, {"temperature": u},
                                            ghost_layers=1, spacing=(2 / (n - 1),) * 3)
                if status != insitu.Status.ok:
                    sys.exit(f"execute: {status}: {instrument.last_error}")


def explore(archive_path, out_png):
    archive = insitu.open(archive_path)
    steps = archive.steps
    orbit = [0, 90, 180, 270]
    figure, axes = plt.subplots(3, max(len(steps), len(orbit)), figsize=(12, 9))
    for ax in axes.ravel():
        ax.axis("off")
    for ax, step, t in zip(axes[0], steps, archive.times):  # the stored view at every step
        ax.imshow(archive.render(step).srgb8())
        ax.set_title(f"step {step}, t = {t:.1f}")
    last = steps[-1]
    for ax, azimuth in zip(axes[1], orbit):  # new views, synthesised from the proxies
        frame = archive.render(last, azimuth=azimuth, elevation=15)
        ax.imshow(frame.srgb8())
        ax.set_title(f"azimuth {azimuth}, trust {frame.confidence.mean():.2f}")
    intervals = len(archive.proxies(last).intervals) - 1
    for ax, scale in zip(axes[2], [0.0, 0.5, 2.0, 4.0]):  # the lower half of the values faded
        frame = archive.render(last, opacity_scale={j: scale for j in range(intervals // 2)})
        ax.imshow(frame.srgb8())
        ax.set_title(f"low intervals x {scale}")
    figure.tight_layout()
    figure.savefig(out_png)
    return archive


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "python-example"
    os.makedirs(out, exist_ok=True)
    archive_path = os.path.join(out, "heat.cdb")
    simulate(archive_path)
    archive = explore(archive_path, os.path.join(out, "explore.png"))
    print(f"explore_and_simulate: {len(archive.steps)} steps in {archive_path}, "
          f"frames in {os.path.join(out, 'explore.png')}")


if __name__ == "__main__":
    main()
