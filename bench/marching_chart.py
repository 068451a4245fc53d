#!/usr/bin/env python3
"""Chart of bench_marching's CSV (bench/bench_marching.cpp, bench/README.md).

Three panels: ms per frame against the volume's side (sweep "volume", log-log) and against the
image's pixels (sweep "image", log-log), one line per pass, with a dotted line of slope 1 through
each pass's first point (cost linear in the swept size would follow it); and ns per sample of the
single-perspective proxies against L intervals and K layers (sweep "bookkeeping"), beside the
unshaded ground truth of the same frame. Error bars span the best to the maximum frame.

    marching_chart.py CSV PNG
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter  # noqa: E402

PASSES = ["truth_unshaded", "truth_shaded", "single", "multi"]
LABELS = {"truth_unshaded": "ground truth, unshaded", "truth_shaded": "ground truth, shaded",
          "single": "single-perspective proxies", "multi": "multi-perspective proxies"}
DPI = 80


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def size_panel(ax, rows, sweep, x_of, xlabel, tick_label):
    ticks = set()
    for name in PASSES:
        points = sorted((x_of(r), float(r["ms_best"]), float(r["ms_max"]))
                        for r in rows if r["sweep"] == sweep and r["pass"] == name)
        if not points:
            continue
        xs = [p[0] for p in points]
        ticks.update(xs)
        best = [p[1] for p in points]
        spread = [p[2] - p[1] for p in points]
        line = ax.errorbar(xs, best, yerr=[[0] * len(xs), spread], marker="o", capsize=3,
                           label=LABELS[name])
        ax.plot(xs, [best[0] * x / xs[0] for x in xs], ":", color=line[0].get_color())
    ax.set_xscale("log")
    ax.set_yscale("log")
    # The swept sizes as ticks, plain numbers on both axes (log axes default to powers of ten).
    ax.set_xticks(sorted(ticks), [tick_label(x) for x in sorted(ticks)])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(xlabel)
    ax.set_ylabel("ms per frame (best; bar to max)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def bookkeeping_panel(ax, rows):
    rows = [r for r in rows if r["sweep"] == "bookkeeping"]
    truth = [float(r["ns_per_sample"]) for r in rows if r["pass"] == "truth_unshaded"]
    for intervals in sorted({int(r["intervals"]) for r in rows if r["pass"] == "single"}):
        points = sorted((int(r["layers"]), float(r["ns_per_sample"])) for r in rows
                        if r["pass"] == "single" and int(r["intervals"]) == intervals)
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="o",
                label=f"single-perspective proxies, L = {intervals}")
    if truth:
        ax.axhline(truth[0], color="k", linestyle="--", label="ground truth, unshaded")
    ax.set_xlabel("depth layers K")
    ax.set_ylabel("ns per sample (best frame)")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", help="bench_marching --csv output")
    parser.add_argument("png", help="chart to write")
    args = parser.parse_args()
    rows = read(args.csv)
    if not rows:
        raise SystemExit(f"marching_chart.py: {args.csv} has no rows")

    fig, axes = plt.subplots(1, 3, figsize=(17, 5))
    size_panel(axes[0], rows, "volume", lambda r: int(r["volume"]), "volume side (samples)",
               lambda x: f"{x}³")
    axes[0].set_title("against volume size (image fixed)")
    size_panel(axes[1], rows, "image", lambda r: int(r["image"]) ** 2, "image pixels",
               lambda x: f"{round(x ** 0.5)}²")
    axes[1].set_title("against image size (volume fixed)")
    bookkeeping_panel(axes[2], rows)
    axes[2].set_title("per-sample bookkeeping")
    fig.suptitle("bench_marching (dotted: slope 1 through the first point)")
    fig.tight_layout()
    fig.savefig(args.png, dpi=DPI)


if __name__ == "__main__":
    main()
