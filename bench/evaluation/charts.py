#!/usr/bin/env python3
"""Charts and RESULTS.md of the evaluation harness (bench/evaluate).

Reads the CSV files insitu_evaluate and insitu_evaluate_vtk wrote into RESULTS_DIR, draws one
PNG per chart there (matplotlib, Agg) and writes the markdown report, bench/design_figures.md
appended to it. With --check it also verifies that every chart exists and every number in every
CSV is finite, and exits 1 naming what is not (the CI smoke test).

    charts.py RESULTS_DIR --markdown FILE [--image-prefix PREFIX] [--elapsed SECONDS] [--check]
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from crossover_chart import chart_crossover, markdown as crossover_markdown  # noqa: E402

CHARTS = ["pareto", "rotation", "radiality", "clusters", "opacity_edits", "storage", "failures",
          "light_fields", "budget", "budget_light_field", "crossover"]
DPI = 80
SOURCES = {"multi45": "multi-perspective, tilt 45°", "multi20": "multi-perspective, tilt 20°",
           "single": "single perspective"}
# Figures behind design choices, measured once and edited by hand: every RESULTS.md carries them,
# so a full run does not drop what the code's comments point to.
DESIGN_FIGURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir,
                              "design_figures.md")


def read(directory, name):
    path = os.path.join(directory, name + ".csv")
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(row, key):
    return float(row[key])


def pareto_front(points):
    """Points (cost, quality) not dominated by a cheaper-or-equal, better-or-equal point."""
    front = []
    for cost, quality in sorted(points, key=lambda p: (p[0], -p[1])):
        if not front or quality > front[-1][1]:
            front.append((cost, quality))
    return front


def field_label(r):
    """'a 0.01' / 'r 1' for a compressed-field row of volume_field.csv."""
    return "%s %s" % ("a" if r["mode"] == "accuracy" else "r", r["value"])


def chart_pareto(d, rows, primary, volume=()):
    rows = [r for r in rows if r["scene"] == primary]
    volume = [r for r in volume if r["scene"] == primary]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for i, (metric, title) in enumerate(
            [("edit_psnr", "held-out opacity edit (colour model)"),
             ("rotate15_psnr", "view rotated 15° (volumetric synthesis)")]):
        for j, (cost, label) in enumerate(
                [("archive_bytes", "archive MB per step"), ("emission_ms", "emission ms per camera")]):
            ax = axes[i][j]
            scale = 1e-6 if cost == "archive_bytes" else 1.0
            pts = [(num(r, cost) * scale, num(r, metric)) for r in rows]
            # Garbage (e.g. PSNR far below 0 dB) would squash the chart: such points sit on the
            # lower edge as red triangles, labelled with their value.
            floor = max(0.0, min([y for _, y in pts if y >= 0.0] or [0.0]) - 3.0)
            for r, (x, y) in zip(rows, pts):
                value = {"default": "default", "image": r["image"] + "²", "intervals": "L=" + r["intervals"],
                         "clusters": "K=" + r["clusters"], "layers": r["layers"] + " layers",
                         "tilt": "tilt " + r["tilt_deg"], "training": r["training"] + " train",
                         "precision": r["precision"], "compression": r["compression"]}[r["varied"]]
                if y < floor:
                    ax.scatter([x], [floor], s=30, marker="v", color="red")
                    ax.annotate("%s: %.0f dB" % (value, y), (x, floor), fontsize=7, color="red",
                                xytext=(3, 4), textcoords="offset points")
                    continue
                ax.scatter([x], [y], s=18, color="C0" if r["varied"] != "default" else "C3")
                ax.annotate(value, (x, y), fontsize=7, xytext=(3, 2), textcoords="offset points")
            front = pareto_front([p for p in pts if p[1] >= floor])
            # The compressed field: the same measure on the decoded field (section volume).
            field_metric = "stored_edit_psnr" if metric == "edit_psnr" else "rotate15_psnr"
            field_cost = "bytes" if cost == "archive_bytes" else "compress_ms"
            for k, r in enumerate(volume):
                ax.scatter([num(r, field_cost) * scale], [num(r, field_metric)], s=18, marker="^",
                           color="C1", label="compressed field (ZFP)" if k == 0 else None)
                ax.annotate(field_label(r), (num(r, field_cost) * scale, num(r, field_metric)),
                            fontsize=6, color="C1", xytext=(3, -7), textcoords="offset points")
            ax.set_ylim(bottom=floor - 1.0)
            ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="C2",
                    label="Pareto front")
            ax.set_xscale("log")
            ax.set_xlabel(label)
            ax.set_ylabel("PSNR dB")
            ax.set_title(title, fontsize=10)
            ax.legend(fontsize=8, loc="lower right")
    fig.suptitle("Speed and size against accuracy (%s; one parameter varied at a time)" % primary)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "pareto.png"), dpi=DPI)
    plt.close(fig)


def light_field_goals(rows, met, rig_rows=()):
    """The light-field issue's goals (42 cameras, 512^2 maps unless said): rows of the Goals
    table, from the light-field section's rows; the capture's cost from the default light
    field's (LightFieldSettings: 162 cameras at 128^2, attenuation, rims) row of the rig section
    where it ran."""
    def pick(scene, segments="none", map_size="512", attenuation="0", edit="0"):
        return lookup(rows, scene=scene, source="lightfield", cameras="42", map=map_size,
                      depth_bits="8", depth_threshold="0.3", segments=segments,
                      attenuation=attenuation, edit=edit)
    out = []
    scenes = sorted({r["scene"] for r in rows})
    for scene in scenes:
        whole, split = pick(scene), pick(scene, "0.5")
        if not whole or not split:
            continue
        best = min(num(whole, "mean_abs_percent"), num(split, "mean_abs_percent"))
        out.append(["light field, mean abs error per component, 42 cameras at 512² (%s): whole ray / "
                    "split at opacity 0.5" % scene, "≤ 2.0 %",
                    "%.2f / %.2f %%" % (num(whole, "mean_abs_percent"), num(split, "mean_abs_percent")),
                    met(best <= 2.0)])
        default = lookup(rig_rows, scene=scene, cameras="162", map="128")
        if default:
            # The rounds' own ratios decide: the bests of ~10 ms a camera spread by +-20 %.
            best = num(default, "capture_ms_per_camera") / num(default, "proxy_pass_ms_per_camera")
            rounds = default.get("capture_to_proxy_pass_round_median")
            ratio = float(rounds) if rounds else best
            detail = ("%.2f× (median of the rounds' ratios; bests %.2f×, CPU time %.2f×)" %
                      (ratio, best, num(default, "capture_to_proxy_pass_cpu")) if rounds
                      else "%.2f×" % best)
            out.append(["light field capture per camera against one proxy pass of the same pixels "
                        "(%s, the default light field: 162 cameras at 128², attenuation, rims)" % scene,
                        "≤ 1.0×", detail, met(ratio <= 1.0)])
            continue
        out.append(["light field capture per camera against one proxy pass of the same pixels "
                    "(%s, 42 cameras at 512² without attenuation or rims, whole ray / split)" % scene,
                    "≤ 1.0×",
                    "%.2f× / %.2f×" % (num(whole, "capture_ms_per_camera") / num(whole, "proxy_pass_ms_per_camera"),
                                       num(split, "capture_ms_per_camera") / num(split, "proxy_pass_ms_per_camera")),
                    met(num(whole, "capture_ms_per_camera") <= num(whole, "proxy_pass_ms_per_camera"))])
    edits = [r for r in rows if r["source"] == "lightfield" and r["edit"] == "1"]
    if edits:
        out.append(["attenuation light field, held-out opacity edits from random views, 42 cameras at "
                    "256² (%s): against the ground truth (against the edited light field's capture)" %
                    " / ".join(r["scene"] for r in edits), "≥ 35 dB",
                    " / ".join("%.1f (%.1f) dB" % (num(r, "psnr"), num(r, "edit_vs_captured_psnr"))
                               for r in edits),
                    met(min(num(r, "psnr") for r in edits) >= 35)])
    wholes = [pick(scene) for scene in scenes if pick(scene)]
    if wholes:
        out.append(["light field confidence < 0.5: share of wrong pixels (error > 0.1) flagged / of good "
                    "ones (42 cameras at 512², %s)" % " / ".join(r["scene"] for r in wholes),
                    "≥ 90 % / ≤ 10 %",
                    " / ".join("%.0f %% / %.0f %%" % (100 * num(r, "flagged_fraction"),
                                                     100 * num(r, "good_flagged_fraction"))
                               for r in wholes),
                    met(all(num(r, "flagged_fraction") >= 0.9 and num(r, "good_flagged_fraction") <= 0.1
                            for r in wholes))])
    return out


# The proxies an edit's trust reads in the failure sweeps (evaluate.cpp ColourSetup::trust_proxies).
TRUST_PROXIES = [("interleaving", "interleaving counts only (before the entry depth)"),
                 ("default", "the default proxies (+ entry depth)"),
                 ("optical_depth", "+ optical depth")]


def proxies_of(r):
    return r.get("proxies") or "default"


def edit_trust_goals(scale, occlusion, met):
    """The goal rows of the edit trust (issue 17), per set of proxies: over the failure sweeps, the
    worst row's share of wrong pixels flagged (rows where any went wrong) and of right ones
    flagged."""
    goals = []
    for proxies, label in TRUST_PROXIES[1:]:
        rows = [r for r in scale + occlusion if r.get("good_flagged_fraction") and proxies_of(r) == proxies]
        if not rows:
            continue
        wrong = [r for r in rows if num(r, "high_error_fraction") > 0.0]
        worst_flagged = min((num(r, "flagged_fraction") for r in wrong), default=1.0)
        worst_good = max(num(r, "good_flagged_fraction") for r in rows)
        goals.append(["trust for edits < 0.5, %s: share of wrong pixels (error > 0.1) flagged, worst "
                      "sweep row / of right ones flagged, worst row (failure sweeps: opacity scale, "
                      "occlusion; model and recomposition)" % label, "≥ 80 % / ≤ 10 %",
                      "%.0f %% / %.0f %%" % (100 * worst_flagged, 100 * worst_good),
                      met(worst_flagged >= 0.8 and worst_good <= 0.1)])
        # The same pixels pooled over each sweep (every scale, or every training set; both
        # methods): what a user editing across the sweep meets, where the worst row above may be
        # a few hundred pixels of one edit.
        pooled = []
        for sweep in (scale, occlusion):
            sel = [r for r in sweep if r.get("good_fraction") and proxies_of(r) == proxies]
            if not sel:
                continue
            wrong_share = sum(num(r, "high_error_fraction") for r in sel)
            right_share = sum(num(r, "good_fraction") for r in sel)
            flagged = sum(num(r, "high_error_fraction") * num(r, "flagged_fraction")
                          for r in sel) / wrong_share if wrong_share > 0 else 1.0
            good = sum(num(r, "good_fraction") * num(r, "good_flagged_fraction")
                       for r in sel) / right_share if right_share > 0 else 0.0
            pooled.append((flagged, good))
        if len(pooled) == 2:
            goals.append(["trust for edits < 0.5, %s: the same, each sweep's pixels pooled (opacity "
                          "scale / occlusion)" % label, "≥ 80 % / ≤ 10 %",
                          " / ".join("%.0f %% / %.0f %%" % (100 * f, 100 * g) for f, g in pooled),
                          met(all(f >= 0.8 and g <= 0.1 for f, g in pooled))])
    return goals


def size_label(row):
    """' 1/2' for a budget step stored at half each side; '' at the asked size (and in CSVs
    written before the budget chose the size)."""
    divisor = row.get("size_divisor") or "1"
    return "" if divisor == "1" else " 1/%s" % divisor


def chart_budget_runs(d, rows, name, psnr_label, bytes_label, choice_label, log_bytes=False):
    """Budget runs over a Gray-Scott run: per archived step the PSNR asked (dotted), what the
    budget measured in situ (x) and what the archive achieves (and, where the rows have it, in
    views no check measured: dashed); the bytes per step of each run beside the default's, each
    labelled with what it chose (choice_label of a run's rows)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    runs = sorted({r["run"] for r in rows}, key=lambda n: (n != "default", n))
    for k, run in enumerate(runs):
        sel = [r for r in rows if r["run"] == run]
        steps = [num(r, "step") for r in sel]
        axes[0].plot(steps, [num(r, "achieved_psnr_db") for r in sel], "o-", color="C%d" % k,
                     label="%s: achieved" % run.replace("_", " "))
        if "achieved_far_psnr_db" in sel[0]:
            axes[0].plot(steps, [num(r, "achieved_far_psnr_db") for r in sel], "s--",
                         color="C%d" % k, ms=3, lw=0.8)
        if run != "default":
            axes[0].axhline(num(sel[0], "asked_psnr_db"), color="C%d" % k, lw=0.8, ls=":")
            axes[0].plot(steps, [num(r, "measured_psnr_db") for r in sel], "x", color="C%d" % k)
        axes[1].plot(steps, [num(r, "bytes") / 1e6 for r in sel], "o-", color="C%d" % k,
                     label="%s (%s)" % (run.replace("_", " "), choice_label(sel)))
    axes[0].set_ylabel(psnr_label)
    axes[1].set_ylabel(bytes_label)
    if log_bytes:
        axes[1].set_yscale("log")
    for ax in axes:
        ax.set_xlabel("simulation step")
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, name + ".png"), dpi=DPI)
    plt.close(fig)


def chart_budget(d, rows):
    """The error budget over a Gray-Scott run: the held-out edit in the views the budget
    measures; the views' bytes per step beside the default's."""
    chart_budget_runs(d, rows, "budget",
                      "held-out edit PSNR dB, least of the stored view and +-20 deg\n"
                      "(dotted: asked; x: measured in situ)",
                      "archived MB per step (view EXR + preview)",
                      lambda sel: "L = " + "/".join(sorted({r["intervals"] for r in sel}, key=int)))


def chart_budget_light_field(d, rows):
    """The budget's light field over a Gray-Scott run: the run's own function reconstructed
    from it in the budget's views and in views no check measured; its bytes per step beside the
    default rig's."""
    chart_budget_runs(d, rows, "budget_light_field",
                      "light field PSNR dB, least of stored, +-20 deg\n"
                      "(dashed: far views; x: in situ)",
                      "light-field MB per step (EXR)",
                      lambda sel: ", ".join("%d@%d" % rig for rig in sorted(
                          {(int(r["cameras"]), int(r["size"])) for r in sel})),
                      log_bytes=True)


def chart_light_fields(d, rows, volume=()):
    """Light fields (seed 001 Table 1 on our scenes) beside the single-view proxies and their
    per-pixel fusion, all from the same random views: accuracy against bytes, error against
    cameras, capture cost per camera against one single-perspective proxy pass."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    scenes = sorted({r["scene"] for r in rows})
    markers = {"lightfield": "o", "single": "s", "fused": "D"}
    for k, scene in enumerate(scenes):
        colour = "C%d" % k
        mine = [r for r in rows if r["scene"] == scene and r["edit"] == "0"]
        for r in mine:
            x, y = num(r, "stored_bytes") * 1e-6, num(r, "psnr")
            axes[0].scatter([x], [y], s=22, marker=markers[r["source"]], color=colour)
            label = r["source"] if r["source"] != "lightfield" else "%s@%s%s%s" % (
                r["cameras"], r["map"], "" if r["depth_bits"] == "8" else " d16",
                "" if num(r, "depth_threshold") == 0.3 else " t%g" % num(r, "depth_threshold"))
            if r.get("segments", "none") != "none":
                label += " seg " + r["segments"]
            axes[0].annotate(label, (x, y), fontsize=6, xytext=(3, 2), textcoords="offset points")
        front = pareto_front([(num(r, "stored_bytes") * 1e-6, num(r, "psnr")) for r in mine])
        # The compressed field in the same views (section volume), the run's function.
        field = sorted(((num(r, "bytes") * 1e-6, num(r, "psnr"), field_label(r))
                        for r in volume if r["scene"] == scene), key=lambda p: p[0])
        axes[0].scatter([p[0] for p in field], [p[1] for p in field], s=22, marker="^",
                        color=colour, label="%s compressed field (ZFP)" % scene if field else None)
        for x, y, label in field:
            axes[0].annotate(label, (x, y), fontsize=6, xytext=(3, -7), textcoords="offset points")
        axes[0].step([p[0] for p in front], [p[1] for p in front], where="post", color=colour,
                     label="%s Pareto front" % scene)
        for size in sorted({r["map"] for r in mine if r["source"] == "lightfield"}, key=int):
            # The camera sweep at this map size: default settings but for the cameras.
            sweep = [r for r in mine
                     if r["source"] == "lightfield" and r["map"] == size
                     and r["depth_bits"] == "8" and r["attenuation"] == "0"
                     and num(r, "depth_threshold") == 0.3
                     and r.get("segments", "none") == "none"]
            pts = sorted((int(r["cameras"]), num(r, "mean_abs_percent")) for r in sweep)
            axes[1].plot([p[0] for p in pts], [p[1] for p in pts], marker="o", color=colour,
                         linestyle="-" if size == "512" else "--",
                         label="%s, %s² maps" % (scene, size))
            cost = sorted((int(r["cameras"]), num(r, "capture_ms_per_camera"),
                           num(r, "proxy_pass_ms_per_camera")) for r in sweep)
            axes[2].plot([p[0] for p in cost], [p[1] for p in cost], marker="o", color=colour,
                         linestyle="-" if size == "512" else "--",
                         label="%s capture, %s²" % (scene, size))
            axes[2].plot([p[0] for p in cost], [p[2] for p in cost], marker="x", color=colour,
                         linestyle=":", label="%s proxy pass, %s²" % (scene, size))
    axes[0].set_xscale("log")
    axes[0].set_xlabel("MB per step as stored")
    axes[0].set_ylabel("PSNR dB, mean of random views")
    axes[0].set_title("accuracy per byte (o light field, s single view, D fused, ^ ZFP field)",
                      fontsize=10)
    axes[0].legend(fontsize=7, loc="lower right")
    axes[1].axhline(2.0, color="grey", linestyle=":", label="goal 2 %")
    axes[1].set_xscale("log")
    axes[1].set_xlabel("cameras")
    axes[1].set_ylabel("mean abs error per component, %")
    axes[1].set_title("seed 001 Table 1 on our scenes", fontsize=10)
    axes[1].legend(fontsize=7)
    axes[2].set_xscale("log")
    axes[2].set_xlabel("cameras")
    axes[2].set_ylabel("ms per camera")
    axes[2].set_title("capture cost per camera", fontsize=10)
    axes[2].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "light_fields.png"), dpi=DPI)
    plt.close(fig)


def chart_rotation(d, rows):
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    scenes = sorted({r["scene"] for r in rows})
    for k, scene in enumerate(scenes):
        for source, style in [("multi45", "-"), ("multi20", "-."), ("single", "--")]:
            sel = [r for r in rows if r["scene"] == scene and r["source"] == source]
            a = [num(r, "angle_deg") for r in sel]
            label = "%s, %s" % (scene, SOURCES[source])
            axes[0].plot(a, [num(r, "depth_corr") for r in sel], style, color="C%d" % k, label=label)
            axes[1].plot(a, [num(r, "psnr") for r in sel], style, color="C%d" % k, label=label)
            axes[2].plot(a, [num(r, "depth_flagged_fraction") for r in sel], style, color="C%d" % k,
                         label=label + " (depth)")
            if source != "multi20":
                axes[2].plot(a, [num(r, "colour_flagged_fraction") for r in sel], ":", color="C%d" % k,
                             label=label + " (colour)")
    axes[0].plot([15, 30], [0.99, 0.95], "k*", markersize=10, label="goals (15°: 0.99, 30°: 0.95)")
    for ax in axes:
        ax.axvspan(60, 90, color="0.9")
        ax.set_xlabel("rotation from the stored view, degrees (grey: beyond the paper's 60°)")
    axes[0].set_ylabel("depth correlation (layer 0)")
    axes[0].set_title("seed 000 Fig. 6a: depth correlation vs rotation", fontsize=10)
    axes[1].set_ylabel("PSNR dB")
    axes[1].set_title("volumetric view synthesis, colour", fontsize=10)
    axes[2].set_ylabel("fraction of high-error pixels flagged")
    axes[2].set_ylim(-0.05, 1.05)
    axes[2].set_title("confidence-mask coverage of what went wrong", fontsize=10)
    for ax in axes:
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "rotation.png"), dpi=DPI)
    plt.close(fig)


def chart_radiality(d, rows, curvature):
    scenes = []
    for r in rows:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
    summary = {r["scene"]: r for r in curvature}
    fig, axes = plt.subplots(1, len(scenes) + 1, figsize=(3.4 * (len(scenes) + 1), 3.4))
    for ax, scene in zip(axes, scenes):
        sel = [r for r in rows if r["scene"] == scene]
        lo = [num(r, "bin_low_deg") for r in sel]
        width = [num(r, "bin_high_deg") - num(r, "bin_low_deg") for r in sel]
        ax.bar(lo, [num(r, "fraction") for r in sel], width=width, align="edge", color="C0")
        s = summary.get(scene)
        title = scene if not s else "%s\nmean %.0f°, corr@30° %.3f" % (
            scene, num(s, "mean_radiality_deg"), num(s, "corr_30"))
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("ray-normal angle, degrees")
    axes[0].set_ylabel("fraction of hit pixels")
    ax = axes[-1]
    for k, s in enumerate(curvature):
        for angle, marker in [("corr_15", "o"), ("corr_30", "s"), ("corr_60", "^")]:
            ax.scatter([num(s, "mean_radiality_deg")], [num(s, angle)], marker=marker, color="C%d" % k,
                       label="%s %s°" % (s["scene"], angle[5:]))
    ax.set_xlabel("mean radiality, degrees")
    ax.set_ylabel("depth correlation")
    ax.set_title("curvature predicts rotation error", fontsize=9)
    ax.legend(fontsize=5)
    fig.suptitle("seed 000 Fig. 6b-d: radiality histograms (multi-perspective, tilt 45°)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "radiality.png"), dpi=DPI)
    plt.close(fig)


def chart_clusters(d, rows):
    fig, ax = plt.subplots(figsize=(6, 4))
    k = [num(r, "clusters") for r in rows]
    ax.plot(k, [num(r, "psnr_mean") for r in rows], "o-", label="mean over held-out edits")
    ax.plot(k, [num(r, "psnr_min") for r in rows], "s--", label="worst held-out edit")
    ax.axhline(35, color="k", lw=0.8, ls=":", label="goal 35 dB")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("clusters K")
    ax.set_ylabel("PSNR dB")
    ax.set_title("seed 000 Fig. 12: prediction error vs K (3 training images)", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "clusters.png"), dpi=DPI)
    plt.close(fig)


def chart_opacity_edits(d, rows):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    series = [("model", n, "%d training image%s" % (n, "s" if n > 1 else "")) for n in (1, 2, 3)]
    series.append(("recompose", 0, "recomposition (no model)"))
    for method, n, label in series:
        sel = [r for r in rows if r["method"] == method and int(r["training_images"]) == n]
        e = [int(r["edit"]) + 1 for r in sel]
        axes[0].plot(e, [num(r, "ssd") for r in sel], "o-", label=label)
        axes[1].plot(e, [num(r, "psnr") for r in sel], "o-", label=label)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("SSD (sum of squared RGB differences)")
    axes[1].set_ylabel("PSNR dB")
    axes[1].axhline(35, color="k", lw=0.8, ls=":", label="goal 35 dB")
    for ax in axes:
        ax.set_xlabel("opacity edit (progressively fading the outer structures)")
        ax.legend(fontsize=8)
    fig.suptitle("seed 000 Fig. 13: error over a sequence of held-out opacity edits", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "opacity_edits.png"), dpi=DPI)
    plt.close(fig)


def chart_storage(d, rows):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    raw = [r for r in rows if r["kind"] == "raw_float32"]
    ax.plot([num(r, "volume_n") for r in raw], [num(r, "bytes") for r in raw], "k-o", label="volume, float32")
    combos = sorted({(int(r["image"]), int(r["layers"])) for r in rows if r["kind"] == "computed_uncompressed"})
    for i, (image, layers) in enumerate(combos):
        sel = [r for r in rows if r["kind"] == "computed_uncompressed" and int(r["image"]) == image
               and int(r["layers"]) == layers]
        ax.plot([num(r, "volume_n") for r in sel], [num(r, "bytes") for r in sel], "--",
                color="C%d" % (i // 3), alpha=0.4 + 0.2 * (i % 3),
                label="proxies %d², k=%d, L=16 (computed, uncompressed)" % (image, layers))
    meas = [r for r in rows if r["kind"] == "measured_half_zip"]
    ax.plot([num(r, "volume_n") for r in meas], [num(r, "bytes") for r in meas], "r*", markersize=12,
            label="measured archive step (%s², k=4, half+zip)" % (meas[0]["image"] if meas else "?"))
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("volume side N (N³ samples)")
    ax.set_ylabel("bytes")
    ax.set_title("seed 000 Fig. 15a: storage of proxies vs volume", fontsize=10)
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "storage.png"), dpi=DPI)
    plt.close(fig)


def chart_failures(d, scale_rows, interval_rows, occlusion_rows, cluster_rows):
    fig, axes = plt.subplots(1, 4, figsize=(18, 4))
    ax = axes[0]
    for method in ("model", "recompose"):
        for proxies, style, suffix in (("default", "o-", ""), ("optical_depth", "s--", ", with optical depth")):
            sel = [r for r in scale_rows if r["method"] == method and proxies_of(r) == proxies]
            if sel:
                ax.plot([num(r, "scale") for r in sel], [num(r, "psnr") for r in sel], style,
                        label=method + suffix)
    ax.axvspan(0.2, 1.0, color="C2", alpha=0.15, label="training range")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("opacity scale on every interval")
    ax.set_ylabel("PSNR dB")
    ax.set_title("opacity far outside the training range", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1]
    L = [num(r, "intervals") for r in interval_rows]
    for key, label in [("edit_model_psnr", "opacity edit, model"), ("edit_recompose_psnr", "opacity edit, recompose"),
                       ("recolour_smooth_psnr", "recolour, smooth colours"),
                       ("recolour_piecewise_psnr", "recolour, colours constant per interval")]:
        ax.plot(L, [num(r, key) for r in interval_rows], "o-", label=label)
    ax.axhline(50, color="k", lw=0.8, ls=":", label="recolour goal 50 dB")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("intervals L")
    ax.set_ylabel("PSNR dB")
    ax.set_title("too few intervals", fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[2]
    occlusion_rows = [r for r in occlusion_rows if proxies_of(r) == "default"]
    labels = ["%s\n%s" % (r["training"].replace("_", " "), r["method"]) for r in occlusion_rows]
    ax.bar(range(len(occlusion_rows)), [num(r, "psnr") for r in occlusion_rows],
           color=["C3" if r["training"] == "inner_occluded" and r["method"] == "model" else "C0" for r in occlusion_rows])
    ax.set_xticks(range(len(occlusion_rows)))
    ax.set_xticklabels(labels, fontsize=7)
    ax.set_ylabel("PSNR dB")
    ax.set_title("feature occluded in every training image", fontsize=10)
    ax = axes[3]
    ax.plot([num(r, "clusters") for r in cluster_rows], [num(r, "psnr_min") for r in cluster_rows], "o-")
    ax.set_xscale("log", base=2)
    ax.set_xlabel("clusters K (K = 1: one linear fit)")
    ax.set_ylabel("worst held-out edit, PSNR dB")
    ax.set_title("K = 1", fontsize=10)
    fig.suptitle("Where the methods fail", fontsize=11)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "failures.png"), dpi=DPI)
    plt.close(fig)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def lookup(rows, **match):
    for r in rows:
        if all(r.get(k) == v for k, v in match.items()):
            return r
    return None


def write_markdown(d, path, prefix, elapsed):
    machine = {r["key"]: r["value"] for r in read(d, "machine")}
    configs = read(d, "configurations")
    rotation = read(d, "rotation")
    curvature = read(d, "curvature")
    edits = read(d, "opacity_edits")
    intervals = read(d, "intervals")
    scale = read(d, "opacity_scale")
    occlusion = read(d, "occlusion")
    clusters = read(d, "clusters")
    storage = read(d, "storage")
    peer = read(d, "peer")
    peer_acc = read(d, "peer_accuracy")
    peer_rounds = read(d, "peer_rounds")
    primary = edits[0]["scene"] if edits else "?"
    rot_scene = rotation[0]["scene"] if rotation else "?"

    def rot(angle, source="multi45", key="depth_corr"):
        r = lookup(rotation, scene=rot_scene, source=source, angle_deg=str(angle))
        return num(r, key) if r else float("nan")

    def met(ok):
        return "**met**" if ok else "**not met**"

    # The goal rows report the source Explorer uses for a new view by default (single
    # perspective when the archive has it: ahead of both tilts at every angle measured).
    c15, c30 = rot(15, "single"), rot(30, "single")
    three = [r for r in edits if r["method"] == "model" and r["training_images"] == "3"]
    edit_min = min(num(r, "psnr") for r in three) if three else float("nan")
    edit_mean = sum(num(r, "psnr") for r in three) / len(three) if three else float("nan")
    default = lookup(configs, scene=primary, varied="default")
    l16 = lookup(intervals, intervals="16")
    recolour_float = num(l16, "recolour_piecewise_psnr") if l16 else float("nan")
    recolour_half = num(default, "recolour_psnr") if default else float("nan")
    stored_rows = [r for r in configs if r["varied"] == "default" and r.get("stored_psnr")]
    stored_worst = min((num(r, "stored_psnr") for r in stored_rows), default=float("nan"))
    stored_text = ", ".join("%s %.1f (%.1f)" % (r["scene"], num(r, "stored_psnr"),
                                                num(r, "stored_recomposed_psnr"))
                            for r in stored_rows)

    lines = ["# Evaluation results", "",
             "Generated by `bench/evaluate` (%s run, %.0f s); do not edit by hand. CSV files and charts: "
             "`bench/results/`. Machine: %s, %s hardware threads; OpenCL device: %s." % (
                 machine.get("mode", "?"), elapsed, machine.get("cpu", "?"),
                 machine.get("hardware_threads", "?"), machine.get("opencl_device", "?")), "",
             "Errors are against the ground-truth renderer on the same view and transfer function "
             "(unshaded, 1-voxel step, no early termination); PSNR on premultiplied RGB over black, "
             "SSIM on luminance (11x11 Gaussian window), depth correlation = Pearson r over pixels finite "
             "in both (insitu/testing/metrics.hpp). Stored view: orthographic, azimuth 30°, elevation 20°; "
             "the primary field is the Gray-Scott v field (%s)." % primary, "",
             "## Goals", "",
             table(["goal", "target", "measured", ""], [
                 ["view synthesis, depth correlation at 15° (%s, single perspective: Explorer's default)" % rot_scene, "≥ 0.99",
                  "%.4f" % c15, met(c15 >= 0.99)],
                 ["view synthesis, depth correlation at 30°", "≥ 0.95", "%.4f" % c30, met(c30 >= 0.95)],
                 ["held-out opacity edits in the training range, 3 training images (worst / mean of %d)" % len(three),
                  "≥ 35 dB", "%.1f / %.1f dB" % (edit_min, edit_mean), met(edit_min >= 35)],
                 ["recolouring, colours constant per interval (float in memory / half from the archive)",
                  "≥ 50 dB", "%.1f / %.1f dB" % (recolour_float, recolour_half),
                  met(min(recolour_float, recolour_half) >= 50)],
                 ["stored view with the run's own function, default configuration, half: the stored "
                  "rendering (recomposed from the intervals), dB", "≥ 60 dB", stored_text or "n/a",
                  met(stored_worst >= 60)],
             ] + edit_trust_goals(scale, occlusion, met) + light_field_goals(read(d, "light_fields"), met,
                                                                 read(d, "light_field_rig"))),
             ""]
    lines += ["Depth correlation by proxy source (%s; the goal rows above use the single-perspective "
              "proxies, which Explorer prefers; tilt 45° is the configuration default and the paper's "
              "Eq. 1):" % rot_scene, "",
              table(["source", "0°", "15°", "30°", "60°", "90°"],
                    [[SOURCES[src]] + ["%.4f" % rot(a, src) for a in (0, 15, 30, 60, 90)]
                     for src in ("multi45", "multi20", "single")]), ""]

    lines += ["## Speed and size against accuracy", "", "![pareto](%spareto.png)" % prefix, ""]
    header = ["scene", "varied", "image", "L", "K", "layers", "tilt", "train", "precision", "compr.",
              "emission ms", "archive MB", "synthesis ms", "edit PSNR", "edit SSIM", "recolour PSNR",
              "rot15 PSNR", "corr 15°", "corr 30°"]
    body = []
    for r in configs:
        body.append([r["scene"], r["varied"], r["image"], r["intervals"], r["clusters"], r["layers"],
                     r["tilt_deg"], r["training"], r["precision"], r["compression"],
                     "%.1f" % num(r, "emission_ms"), "%.2f" % (num(r, "archive_bytes") / 1e6),
                     "%.1f" % num(r, "synthesis_ms"), "%.1f" % num(r, "edit_psnr"),
                     "%.4f" % num(r, "edit_ssim"), "%.1f" % num(r, "recolour_psnr"),
                     "%.1f" % num(r, "rotate15_psnr"), "%.4f" % num(r, "depth_corr_15"),
                     "%.4f" % num(r, "depth_corr_30")])
    lines += [table(header, body), ""]

    light = read(d, "light_fields")
    if light:
        lines += ["## Light fields (seed 001 Table 1 on our scenes)", "",
                  "![light fields](%slight_fields.png)" % prefix, "",
                  "Mean over %s random views (uniform over the sphere of directions) against the "
                  "ground truth; mean abs error per colour component is premultiplied linear RGB "
                  "x 255 over every pixel (the seed's measure) and over the pixels either image "
                  "covers; coverage: share of the truth's hit pixels (alpha > 0.01) within 0.1; "
                  "flagged: confidence < 0.5, among the covered pixels with error > 0.1 (wrong) "
                  "and <= 0.1 (good). 'single' and 'fused' are the stored view's single-perspective "
                  "proxies and the per-pixel fusion of both (Explorer source auto) from the same "
                  "views." % light[0]["views"], ""]
        # The section may come from its own run (insitu_evaluate --sections light_fields),
        # on another machine than the rest: say which.
        own = {r["key"]: r["value"] for r in read(d, "light_fields_machine")}
        if own:
            lines += ["Measured by `insitu_evaluate --sections light_fields` on %s (%s hardware "
                      "threads; %s)." % (own.get("cpu", "?"), own.get("hardware_threads", "?"),
                                         own.get("opencl_device", "?")), ""]
        header = ["scene", "source", "cameras", "map", "depth bits", "threshold", "segments",
                  "attenuation", "edit",
                  "capture ms/camera", "proxy pass ms", "raw MB", "stored MB", "mean abs (0-255)",
                  "mean abs %", "covered mean abs", "PSNR", "SSIM", "coverage", "wrong flagged",
                  "good flagged", "ms/frame", "edit vs edited capture PSNR"]
        body = [[r["scene"], r["source"], r["cameras"], r["map"], r["depth_bits"],
                 r["depth_threshold"], r.get("segments", "none"), r["attenuation"], r["edit"], "%.2f" % num(r, "capture_ms_per_camera"),
                 "%.2f" % num(r, "proxy_pass_ms_per_camera"), "%.1f" % (num(r, "raw_bytes") / 1e6),
                 "%.2f" % (num(r, "stored_bytes") / 1e6), "%.2f" % num(r, "mean_abs_255"),
                 "%.2f" % num(r, "mean_abs_percent"), "%.2f" % num(r, "mean_abs_covered_255"),
                 "%.1f" % num(r, "psnr"), "%.4f" % num(r, "ssim"), "%.3f" % num(r, "coverage"),
                 "%.0f%%" % (100 * num(r, "flagged_fraction")),
                 "%.0f%%" % (100 * num(r, "good_flagged_fraction")),
                 "%.0f" % num(r, "reconstruct_ms"),
                 "%.1f" % num(r, "edit_vs_captured_psnr") if r.get("edit_vs_captured_psnr") else ""]
                for r in light]
        lines += [table(header, body), ""]

    lines += volume_markdown(read(d, "volume_field"))
    # The crossover may come from its own run (insitu_evaluate --sections crossover): say where.
    own = {r["key"]: r["value"] for r in read(d, "crossover_machine")}
    lines += crossover_markdown(read(d, "crossover"), own or machine, prefix)

    lines += ["## View synthesis against rotation (Fig. 6)", "", "![rotation](%srotation.png)" % prefix, "",
              "![radiality](%sradiality.png)" % prefix, ""]
    body = [[r["scene"], "%.1f" % num(r, "mean_radiality_deg"), "%.4f" % num(r, "corr_15"),
             "%.4f" % num(r, "corr_30"), "%.4f" % num(r, "corr_60"), "%.1f" % num(r, "psnr_30")]
            for r in curvature]
    lines += [table(["field", "mean radiality °", "corr 15°", "corr 30°", "corr 60°", "PSNR 30° dB"], body), ""]

    lines += ["## Colour model and opacity edits (Figs. 12, 13)", "",
              "![clusters](%sclusters.png)" % prefix, "", "![opacity edits](%sopacity_edits.png)" % prefix, ""]
    budget = read(d, "budget")
    if budget:
        lines += ["## Error budget over a Gray-Scott run", "", "![budget](%sbudget.png)" % prefix, "",
                  "Per run: the PSNR asked of the held-out edit (the run's function with every opacity "
                  "halved), the worst achieved over the archived steps (measured here through the "
                  "Explorer against the ground truth, the least of the stored view and the views "
                  "turned 20 degrees either way, as the budget measures it; the stored view's own "
                  "beside it), the steps that met it, the intervals, precision and size chosen "
                  "(1/2: each side halved, shown enlarged against the truth at the asked 256²), "
                  "the mean bytes and in-situ time per step and the budget checks' own time; "
                  "'default' is the fixed 16 uniform intervals in half at the asked size.", ""]
        body = []
        for run in sorted({r["run"] for r in budget}, key=lambda n: (n != "default", n)):
            sel = [r for r in budget if r["run"] == run]
            asked = num(sel[0], "asked_psnr_db") if sel[0]["asked_psnr_db"] else float("nan")
            achieved = [num(r, "achieved_psnr_db") for r in sel]
            met_steps = sum(1 for a in achieved if not math.isfinite(asked) or a >= asked)
            stored = [num(r, "achieved_stored_psnr_db") for r in sel]
            ms = [num(r, "ms") for r in sel if r["ms"]]
            checks = [num(r, "check_ms") / 1e3 for r in sel if r.get("check_ms")]
            body.append([run.replace("_", " "), "%.0f" % asked if math.isfinite(asked) else "-",
                         "%.1f" % min(achieved), "%.1f" % min(stored),
                         "%d / %d" % (met_steps, len(sel)),
                         ", ".join(sorted({"%s %s %s%s" % (r["intervals"], r["mode"], r["precision"],
                                                           size_label(r)) for r in sel})),
                         "%.2f" % (sum(num(r, "bytes") for r in sel) / len(sel) / 1e6),
                         "%.0f" % (sum(ms) / len(ms)) if ms else "-",
                         "%.1f-%.1f" % (min(checks), max(checks)) if checks else "-"])
        lines += [table(["run", "asked dB", "worst achieved dB", "stored view's worst dB",
                         "steps met", "intervals, precision, size", "MB / step", "budget's ms / step",
                         "check s"], body), ""]
    budget_lf = read(d, "budget_light_field")
    if budget_lf:
        lines += ["The light field the budget chooses (a light field without attenuation at 256² maps, so the "
                  "run's own function is what it shows and what is measured; the views' settings "
                  "fixed): per run the PSNR asked, the worst achieved over the archived steps "
                  "(through the Explorer's lightfield source against the ground truth, the least "
                  "of the stored view and +-20 degrees, as the budget measures it), the worst in "
                  "views no check measures (azimuth +90 and +180 degrees at the stored elevation, "
                  "and 70 degrees up), the steps that met it, the rigs chosen (cameras@map size), "
                  "the mean light-field bytes and capture time per step and the checks' own time "
                  "(views and light field); 'default' is the default rig (162 cameras at 128²; "
                  "42 at 256² in runs before 2026-12-07).", "",
                  "![budget light field](%sbudget_light_field.png)" % prefix, ""]
        body = []
        for run in sorted({r["run"] for r in budget_lf}, key=lambda n: (n != "default", n)):
            sel = [r for r in budget_lf if r["run"] == run]
            asked = num(sel[0], "asked_psnr_db") if sel[0]["asked_psnr_db"] else float("nan")
            achieved = [num(r, "achieved_psnr_db") for r in sel]
            met_steps = sum(1 for a in achieved if not math.isfinite(asked) or a >= asked)
            ms = [num(r, "ms") for r in sel if r["ms"]]
            checks = [num(r, "check_ms") / 1e3 for r in sel if r.get("check_ms")]
            rigs = sorted({(int(r["cameras"]), int(r["size"])) for r in sel})
            body.append([run.replace("_", " "), "%.0f" % asked if math.isfinite(asked) else "-",
                         "%.1f" % min(achieved),
                         "%.1f" % min(num(r, "achieved_far_psnr_db") for r in sel),
                         "%d / %d" % (met_steps, len(sel)),
                         ", ".join("%d@%d" % rig for rig in rigs),
                         "%.2f" % (sum(num(r, "bytes") for r in sel) / len(sel) / 1e6),
                         "%.0f" % (sum(ms) / len(ms)) if ms else "-",
                         "%.1f-%.1f" % (min(checks), max(checks)) if checks else "-"])
        lines += [table(["run", "asked dB", "worst achieved dB", "worst far view dB", "steps met",
                         "cameras@size", "MB / step", "capture ms / step", "check s"], body), ""]
    lines += ["## Storage (Fig. 15a)", "", "![storage](%sstorage.png)" % prefix, ""]
    meas = [r for r in storage if r["kind"] == "measured_half_zip"]
    if meas:
        lines += [table(["volume", "raw float32 MB", "archive step MB (measured)", "ratio"],
                        [["%s³" % r["volume_n"], "%.1f" % (int(r["volume_n"]) ** 3 * 4 / 1e6),
                          "%.2f" % (num(r, "bytes") / 1e6),
                          "%.1f×" % (int(r["volume_n"]) ** 3 * 4 / num(r, "bytes"))] for r in meas]), ""]

    lines += ["## Where the methods fail", "", "![failures](%sfailures.png)" % prefix, ""]
    def good(r):
        return "%.2f" % num(r, "good_flagged_fraction") if r.get("good_flagged_fraction") else "n/a"
    def by_proxies(rows, keys):
        """Rows of the default proxies, each with its interleaving-only and optical-depth twins."""
        twins = {}
        for r in rows:
            twins.setdefault(tuple(r[k] for k in keys), {})[proxies_of(r)] = r
        return [t for t in twins.values() if "default" in t]
    def mask(r):
        return "%.2f / %s" % (num(r, "flagged_fraction"), good(r)) if r else "n/a"
    def trust_columns(t):
        tau = t.get("optical_depth")
        return ["%.1f" % num(t["default"], "psnr"), "%.3f" % num(t["default"], "high_error_fraction"),
                mask(t.get("interleaving")), mask(t["default"]),
                "%.1f" % num(tau, "psnr") if tau else "n/a",
                "%.3f" % num(tau, "high_error_fraction") if tau else "n/a", mask(tau)]
    trust_header = ["PSNR dB", "high-error px", "flagged / right flagged, interleaving only",
                    "flagged / right flagged, default (+ entry depth)", "PSNR dB, + optical depth",
                    "high-error px, + optical depth", "flagged / right flagged, + optical depth"]
    body = [[t["default"]["scale"], "yes" if t["default"]["in_training_range"] == "1" else "no",
             t["default"]["method"]] + trust_columns(t)
            for t in by_proxies(scale, ("scale", "method"))]
    lines += ["Opacity scaled on every interval (pixels off by > 0.1 of full scale; the share of them the "
              "edit's trust flags, trust < 0.5, and the share of right pixels it flags among those either "
              "image covers; insitu/explore/transfer_function_edit.hpp). The trust reads the interleaving "
              "counts alone (as before the entry depth), the default proxies, or these with the optical "
              "depth, which the estimate then also reads for strong thinning:", "",
              table(["scale", "in training range", "method"] + trust_header, body), ""]
    body = [[t["default"]["training"].replace("_", " "), t["default"]["method"]] + trust_columns(t)
            for t in by_proxies(occlusion, ("training", "method"))]
    lines += ["A feature occluded in every training image (nested shells, the outer one opaque in all "
              "training functions, then faded by the edit to 0.3):", "",
              table(["training images", "method"] + trust_header, body), ""]
    rot_rows = [r for r in rotation if r["scene"] == rot_scene and r["source"] == "multi45"
                and float(r["angle_deg"]) in (15.0, 30.0, 60.0, 90.0)]
    body = [[r["angle_deg"], "%.4f" % num(r, "depth_corr"), "%.3f" % num(r, "depth_high_error_fraction"),
             "%.2f" % num(r, "depth_flagged_fraction"), "%.1f" % num(r, "psnr"),
             "%.3f" % num(r, "colour_high_error_fraction"), "%.2f" % num(r, "colour_flagged_fraction")]
            for r in rot_rows]
    lines += ["Rotation (%s, multi-perspective 45°): high-error pixels (depth off by > 2 voxels or a "
              "surface missing/invented; colour off by > 0.1) and the fraction the mask flagged:" % rot_scene, "",
              table(["angle °", "depth corr", "depth high-error px", "flagged", "PSNR dB",
                     "colour high-error px", "flagged"], body), ""]
    body = [[r["intervals"], "%.1f" % num(r, "edit_model_psnr"), "%.1f" % num(r, "edit_recompose_psnr"),
             "%.1f" % num(r, "recolour_smooth_psnr"), "%.1f" % num(r, "recolour_piecewise_psnr")] for r in intervals]
    lines += ["Intervals:", "", table(["L", "edit, model dB", "edit, recompose dB", "recolour smooth dB",
                                       "recolour per-interval dB"], body), ""]

    lines += ["## Peer: VTK's CPU ray caster", ""]
    if peer:
        vtk = lookup(peer, renderer="vtk_fixed_point")
        body = [[r["renderer"], "%s³" % r["volume_n"], "%s²" % r["image"], "%.1f" % num(r, "ms_per_frame"),
                 "%.1f" % num(r, "ms_median"), "%.1f" % num(r, "ms_max"),
                 "%.1f" % (num(r, "samples") / 1e6),
                 "%.2f" % (1e6 * num(r, "ms_per_frame") / num(r, "samples")),
                 "%.2f×" % (num(r, "ms_per_frame") / num(vtk, "ms_per_frame"))] for r in peer]
        lines += [table(["renderer", "volume", "image", "ms per frame (best)", "median", "slowest",
                         "M samples", "ns per sample", "vs VTK"], body), ""]
        if peer_rounds:
            # Each round's ratios (issue 45): a round where VTK met a burst of load shows here.
            body = [[r["round"], "%.1f" % num(r, "vtk_ms"), "%.1f" % num(r, "ground_truth_ms"),
                     "%.2f×" % num(r, "ground_truth_x"), "%.1f" % num(r, "single_ms"),
                     "%.2f×" % num(r, "single_x"), "%.2f×" % num(r, "all_x"),
                     "%.2f× / %.2f× / %.2f×" % (num(r, "ground_truth_cpu_x"), num(r, "single_cpu_x"),
                                              num(r, "all_cpu_x"))] for r in peer_rounds]
            lines += ["Every round (ms; ratios to VTK's frame of the same round; CPU time: the "
                      "ratios of the CPU time each spent, which other processes' load moves less):",
                      "", table(["round", "VTK", "ground truth", "vs VTK", "single", "vs VTK",
                                 "all proxies vs VTK", "CPU time: truth / single / all"], body), ""]
        if peer_acc:
            lines += ["PSNR between VTK's image and our ground truth: %.2f dB (SSIM %.4f)." % (
                num(peer_acc[0], "psnr_ours_vs_vtk"), num(peer_acc[0], "ssim_ours_vs_vtk")), ""]
        ms = {r["renderer"]: num(r, "ms_per_frame") for r in peer}
        per_sample = {r["renderer"]: num(r, "ms_per_frame") / num(r, "samples") for r in peer}
        v = ms["vtk_fixed_point"]
        lines += ["Goals (issue 13, best of the rounds, one run):", "",
                  "- ground truth, unshaded, ≤ 0.5× one VTK frame: %s (%.2f×)" % (
                      met(ms["ours_ground_truth"] <= 0.5 * v), ms["ours_ground_truth"] / v),
                  "- shaded ≤ 2× unshaded: %s (%.2f×)" % (
                      met(ms["ours_ground_truth_shaded"] <= 2 * ms["ours_ground_truth"]),
                      ms["ours_ground_truth_shaded"] / ms["ours_ground_truth"]),
                  "- all single-perspective proxies of the camera in one pass ≤ 1.0× one VTK frame: "
                  "%s (%.2f×)" % (met(ms["ours_proxies_single"] <= v), ms["ours_proxies_single"] / v),
                  "- multi-perspective, the same cost per sample as single perspective (within 10 %%): "
                  "%s (%.2f×)" % (
                      met(per_sample["ours_proxies_multi"] <= 1.1 * per_sample["ours_proxies_single"]),
                      per_sample["ours_proxies_multi"] / per_sample["ours_proxies_single"]),
                  "", "![peer](%speer.png)" % prefix, ""]
    else:
        reason = open(os.path.join(d, "peer_error.txt")).read().strip() if os.path.exists(
            os.path.join(d, "peer_error.txt")) else "not run"
        lines += ["Not run: %s" % reason, ""]

    lines += ["## What they mean", ""]
    lines += [meaning(configs, primary, c15, c30, edit_min, rotation, rot_scene, occlusion, scale), ""]
    lines += ["## Figures behind design choices", "", design_figures(), ""]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def volume_markdown(rows):
    """The compressed field beside the light fields: what section volume measured."""
    if not rows:
        return []
    header = ["scene", "ZFP", "tolerance (field units)", "MB", "ratio", "compress ms",
              "decompress ms", "PSNR, run's function (least)", "PSNR, held-out edits (least)",
              "stored view edit PSNR", "turned 15° PSNR"]
    body = [[r["scene"], r["setting"], "%.3g" % num(r, "tolerance") if num(r, "tolerance") else "",
             "%.3f" % (num(r, "bytes") / 1e6), "%.1f×" % (num(r, "raw_bytes") / num(r, "bytes")),
             "%.0f" % num(r, "compress_ms"), "%.0f" % num(r, "decompress_ms"),
             "%.1f (%.1f)" % (num(r, "psnr"), num(r, "psnr_min")),
             "%.1f (%.1f)" % (num(r, "edit_psnr"), num(r, "edit_psnr_min")),
             "%.1f" % num(r, "stored_edit_psnr"), "%.1f" % num(r, "rotate15_psnr")] for r in rows]
    return ["## The compressed field in the light fields' views", "",
            "The field itself through ZFP 1.0 (raw libzfp, serial, full header; fixed accuracy as a "
            "share of the value range, or fixed rate in bits per value), decoded and rendered by "
            "the ground-truth renderer with the same settings, in the light-field section's %s "
            "random views with the run's function and its held-out edits, and in the "
            "configuration grid's stored-view edit and 15° turn (its ^ points in the light-field "
            "and Pareto charts). Times: median of 3 after a warm-up, one thread. PSNR is capped "
            "at 100 dB (identical images)." % rows[0]["views"], "", table(header, body), ""]


def design_figures():
    """bench/design_figures.md without its title, which the report's own heading replaces."""
    with open(DESIGN_FIGURES, encoding="utf-8") as f:
        text = f.read()
    if text.startswith("# "):
        text = text.split("\n", 1)[1]
    return text.strip("\n")


def meaning(configs, primary, c15, c30, edit_min, rotation, rot_scene, occlusion, scale):
    prim = [r for r in configs if r["scene"] == primary]
    default = lookup(prim, varied="default")
    s1 = ("Transfer-function edits are where proxies are strong: a held-out opacity edit predicted by the "
          "colour model stays at %.1f dB or better with 3 training images, while an archive step costs %.2f MB "
          "and its emission %.0f ms per camera, so cost is set by the image size and L, not by accuracy knobs "
          "such as K, precision or compression." % (edit_min, num(default, "archive_bytes") / 1e6,
                                                      num(default, "emission_ms"))) if default else ""
    r90 = lookup(rotation, scene=rot_scene, source="multi45", angle_deg="90")
    s2 = ("View synthesis is where they are weak: on %s the depth correlation of the single-perspective proxies Explorer synthesises from is "
          "%.3f at 15° and %.3f at 30° and keeps falling toward 90°, and the confidence mask flags %.0f%% of the "
          "pixels that went wrong at 90°." % (rot_scene, c15, c30,
                                               100 * num(r90, "depth_flagged_fraction") if r90 else float("nan")))
    occlusion = [r for r in occlusion if proxies_of(r) == "default"]
    occ = lookup(occlusion, training="inner_occluded", method="model")
    far = [r for r in scale if r["method"] == "model" and r["in_training_range"] == "0"
           and proxies_of(r) == "default"]
    worst_far = min(num(r, "psnr") for r in far) if far else float("nan")
    thick = [r for r in far if num(r, "scale") > 1 and num(r, "high_error_fraction") > 0]
    thin = [r for r in far if num(r, "scale") < 1 and num(r, "high_error_fraction") > 0]
    false_alarms = [num(r, "good_flagged_fraction") for r in far if r.get("good_flagged_fraction")]
    def span(rows):
        values = [100 * num(r, "flagged_fraction") for r in rows]
        return "%.0f-%.0f %%" % (min(values), max(values)) if values else "n/a"
    s3 = ("Colour-model failures are no longer silent: a feature hidden in every training image drops "
          "the model to %.1f dB and the edit's trust flags %.0f %% of the pixels that went wrong; "
          "opacity scaled far outside the training range falls to %.1f dB, and with the entry depth "
          "the trust flags %s of the wrong pixels of thickening edits while flagging at most %.0f %% "
          "of the right ones, but only %s of those of thinning edits, which need the optical "
          "depth." % (
              num(occ, "psnr") if occ else float("nan"),
              100 * num(occ, "flagged_fraction") if occ else float("nan"), worst_far, span(thick),
              100 * max(false_alarms, default=float("nan")), span(thin)))
    return " ".join([s1, s2, s3])


def chart_peer(d):
    a, b = os.path.join(d, "peer_vtk.png"), os.path.join(d, "peer_ours.png")
    if not (os.path.exists(a) and os.path.exists(b)):
        return False
    import numpy as np
    ia, ib = plt.imread(a)[..., :3], plt.imread(b)[..., :3]
    fig, axes = plt.subplots(1, 3, figsize=(10, 3.6))
    for ax, img, title in [(axes[0], ia, "VTK fixed point"), (axes[1], ib, "ours (ground truth)"),
                           (axes[2], np.abs(ia - ib).max(axis=2) * 10, "|difference| × 10")]:
        ax.imshow(np.clip(img, 0, 1), cmap="gray" if img.ndim == 2 else None)
        ax.set_title(title, fontsize=9)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "peer.png"), dpi=60)
    plt.close(fig)
    os.remove(a)
    os.remove(b)
    return True


def check(d):
    problems = []
    for name in CHARTS + ["peer"]:
        if not os.path.exists(os.path.join(d, name + ".png")):
            problems.append("missing chart %s.png" % name)
    for file in sorted(os.listdir(d)):
        if not file.endswith(".csv") or file == "machine.csv":
            continue
        rows = read(d, file[:-4])
        if not rows:
            problems.append("%s: no rows" % file)
        for i, r in enumerate(rows):
            for k, v in r.items():
                try:
                    x = float(v)
                except ValueError:
                    continue
                if not math.isfinite(x):
                    problems.append("%s row %d: %s = %s" % (file, i + 1, k, v))
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("results")
    parser.add_argument("--markdown", required=True)
    parser.add_argument("--image-prefix", default="results/")
    parser.add_argument("--elapsed", type=float, default=0.0)
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()
    d = args.results
    configs = read(d, "configurations")
    primary = read(d, "opacity_edits")[0]["scene"]
    volume = read(d, "volume_field")
    chart_pareto(d, configs, primary, volume)
    chart_rotation(d, read(d, "rotation"))
    chart_radiality(d, read(d, "radiality"), read(d, "curvature"))
    chart_clusters(d, read(d, "clusters"))
    chart_opacity_edits(d, read(d, "opacity_edits"))
    chart_storage(d, read(d, "storage"))
    chart_failures(d, read(d, "opacity_scale"), read(d, "intervals"), read(d, "occlusion"), read(d, "clusters"))
    chart_light_fields(d, read(d, "light_fields"), volume)
    chart_crossover(d, read(d, "crossover"))
    chart_budget(d, read(d, "budget"))
    chart_budget_light_field(d, read(d, "budget_light_field"))
    chart_peer(d)
    write_markdown(d, args.markdown, args.image_prefix, args.elapsed)
    if args.check:
        problems = check(d)
        for p in problems:
            print("charts.py: " + p, file=sys.stderr)
        if problems:
            return 1
        print("charts.py: %d charts, every figure finite" % (len(CHARTS) + 1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
