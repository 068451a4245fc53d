"""The crossover chart and its RESULTS.md section (issue 40, item 5), from crossover.csv that
insitu_evaluate's section "crossover" writes: per field, volume size n and function (held-out
edit, sharp), the bytes per step each representation needs to reach 30, 40 and 50 dB over random
views, and the size above which images are cheaper than the compressed field at equal accuracy,
from a power-law fit of bytes against n per representation (least squares of log bytes on log n).
charts.py imports it."""
import math
import os

import matplotlib.pyplot as plt

THRESHOLDS = [25, 30, 40, 50]
IMAGES = ["single", "multi", "lightfield12", "lightfield42", "lightfield162"]
REPRESENTATIONS = ["field"] + IMAGES
LABELS = {"field": "compressed field (ZFP)", "single": "single-view proxies",
          "multi": "multi-perspective proxies", "lightfield12": "light field, 12 cameras",
          "lightfield42": "light field, 42 cameras", "lightfield162": "light field, 162 cameras"}
TFS = [("edit", "held-out edit"), ("sharp", "sharp function (3 peaks, 2 % wide)")]
PROJECTED = [1024, 2048, 4096]


def _num(row, key):
    return float(row[key])


def cheapest(rows, field, n, tf, representations, threshold):
    """The row of least bytes among `representations` whose mean PSNR reaches `threshold`."""
    hits = [r for r in rows if r["field"] == field and int(r["n"]) == n and r["tf"] == tf
            and r["representation"] in representations and _num(r, "psnr") >= threshold]
    return min(hits, key=lambda r: _num(r, "bytes")) if hits else None


def best_psnr(rows, field, n, tf, representation):
    sel = [_num(r, "psnr") for r in rows if r["field"] == field and int(r["n"]) == n
           and r["tf"] == tf and r["representation"] == representation]
    return max(sel) if sel else None


def power_fit(points):
    """log bytes = a + b log n by least squares over (n, bytes); one point: b = 0 (bytes constant
    in n, as an image's are). None without points."""
    if not points:
        return None
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(b) for _, b in points]
    if len(points) == 1 or max(xs) == min(xs):
        return (sum(ys) / len(ys), 0.0)
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    return (my - b * mx, b)


def fit_at(fit, n):
    return math.exp(fit[0] + fit[1] * math.log(n))


def crossover_size(field_fit, image_fit):
    """The n where the fits meet, above which the images are cheaper (None where the field's
    bytes do not grow faster than the images')."""
    if field_fit is None or image_fit is None or field_fit[1] <= image_fit[1]:
        return None
    return math.exp((image_fit[0] - field_fit[0]) / (field_fit[1] - image_fit[1]))


def analyse(rows):
    """Per (field, tf, threshold): the field's and the images' cheapest (n, bytes, representation)
    at each size, their fits and the crossover size."""
    out = []
    fields = sorted({r["field"] for r in rows})
    sizes = sorted({int(r["n"]) for r in rows})
    for field in fields:
        for tf, _ in TFS:
            for threshold in THRESHOLDS:
                f_pts, i_pts = [], []
                for n in sizes:
                    f = cheapest(rows, field, n, tf, ["field"], threshold)
                    i = cheapest(rows, field, n, tf, IMAGES, threshold)
                    if f:
                        f_pts.append((n, _num(f, "bytes"), f["setting"]))
                    if i:
                        i_pts.append((n, _num(i, "bytes"), "%s %s" % (i["representation"], i["setting"])))
                # The images' fit follows one representation, the cheapest at the largest size
                # reaching the PSNR, over the sizes it reaches it (mixing kinds across sizes would
                # fit a slope no representation has).
                if i_pts:
                    kind = i_pts[-1][2].split(" ")[0]
                    i_pts = [p for p in i_pts if p[2].split(" ")[0] == kind]
                f_fit = power_fit([(n, b) for n, b, _ in f_pts])
                i_fit = power_fit([(n, b) for n, b, _ in i_pts])
                out.append({"field": field, "tf": tf, "threshold": threshold, "field_points": f_pts,
                            "image_points": i_pts, "field_fit": f_fit, "image_fit": i_fit,
                            "crossover": crossover_size(f_fit, i_fit)})
    return out


def chart_crossover(d, rows):
    """Bytes per step to reach each accuracy against volume size, field (solid) and the cheapest
    image representation (dashed), fits dotted to 4096^3; and capture/compression ms against n."""
    fields = sorted({r["field"] for r in rows})
    fig, axes = plt.subplots(3, max(1, len(fields)), figsize=(7 * max(1, len(fields)), 13), squeeze=False)
    analysis = analyse(rows)
    sizes = sorted({int(r["n"]) for r in rows})
    span = [min(sizes), 4096] if sizes else [64, 4096]
    for col, field in enumerate(fields):
        for row_i, (tf, tf_label) in enumerate(TFS):
            ax = axes[row_i][col]
            for k, a in enumerate(x for x in analysis if x["field"] == field and x["tf"] == tf):
                colour = "C%d" % k
                for points, fit, style, who in ((a["field_points"], a["field_fit"], "-", "field"),
                                                (a["image_points"], a["image_fit"], "--", "images")):
                    if not points:
                        continue
                    ax.plot([p[0] for p in points], [p[1] / 1e6 for p in points], style, marker="o",
                            color=colour, label="%s, %d dB" % (who, a["threshold"]))
                    xs = [span[0] * (span[1] / span[0]) ** (t / 20) for t in range(21)]
                    ax.plot(xs, [fit_at(fit, x) / 1e6 for x in xs], ":", color=colour, linewidth=0.8)
                if a["crossover"] and span[0] <= a["crossover"] <= 2 * span[1]:
                    ax.axvline(a["crossover"], color=colour, linewidth=0.6, alpha=0.5)
            ax.set_xscale("log", base=2)
            ax.set_yscale("log")
            ax.set_xlabel("volume n (n³ samples)")
            ax.set_ylabel("MB per step to reach the PSNR")
            ax.set_title("%s, %s: mean PSNR over random views\n(solid field, dashed cheapest images; "
                         "dotted: power fit; vertical: crossover)" % (field, tf_label), fontsize=9)
            ax.legend(fontsize=7, ncol=2)
        ax = axes[2][col]
        for k, rep in enumerate(REPRESENTATIONS):
            sel = [r for r in rows if r["field"] == field and r["representation"] == rep and r["tf"] == "edit"]
            if not sel:
                continue
            pts = sorted((int(n), min(_num(r, "ms") for r in sel if int(r["n"]) == n))
                         for n in {int(r["n"]) for r in sel})
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", color="C%d" % k,
                    label=LABELS[rep] + (" compression (least)" if rep == "field" else " capture (least)"))
            if rep == "field":
                dec = sorted((int(n), min(_num(r, "decompress_ms") for r in sel if int(r["n"]) == n))
                             for n in {int(r["n"]) for r in sel})
                ax.plot([p[0] for p in dec], [p[1] for p in dec], ":", marker="x", color="C%d" % k,
                        label="field decompression (least)")
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("volume n")
        ax.set_ylabel("ms per step")
        ax.set_title("%s: the cheapest setting's capture / compression time" % field, fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "crossover.png"), dpi=70)
    plt.close(fig)


def _mb(x):
    return "%.3g" % (x / 1e6)


def _fit_text(fit):
    if fit is None:
        return "—"
    return "%.3g MB · (n/256)^%.2f" % (fit_at(fit, 256) / 1e6, fit[1])


def markdown(rows, machine, prefix):
    """The RESULTS.md section: what was measured, the bytes each representation needs, the fits
    and crossovers, and the projection to 1024^3-4096^3."""
    if not rows:
        return []
    views = sorted({(int(r["n"]), r["views"]) for r in rows})
    lines = ["## The compressed field against images: crossover", "",
             "![crossover](%scrossover.png)" % prefix, "",
             "Measured by `insitu_evaluate --sections crossover` on %s (%s hardware threads; %s). "
             "Gray-Scott v at step 300 and Marschner–Lobb at n³; every representation explored "
             "from the same random views at 256² (views per size: %s) against the ground truth of "
             "the original field, with the held-out opacity edits (one per view) and with a sharp "
             "function no representation saw (three peaks 2 %% of the range wide). The compressed "
             "field: ZFP 1.0 through the archive's codec, serial, full header, fixed accuracy 0.3–1e-4 of the range and "
             "fixed rate 0.25–8 bits, decoded and rendered by the ground-truth renderer; bytes = "
             "the stream. Images: the Instrument's archive of the stored view (single-view "
             "proxies at 128² and 256², multi-perspective proxies the same), attenuation light "
             "fields of 12/42/162 cameras at 128² maps (the EXR as archived; 162 not run at 512³), "
             "Explorer "
             "frames enlarged to 256² where smaller. Least bytes whose mean PSNR reaches the "
             "threshold; '—' = no setting reaches it (best mean PSNR in brackets)." % (
                 machine.get("cpu", "?"), machine.get("hardware_threads", "?"),
                 machine.get("opencl_device", "?"),
                 ", ".join("%d³: %s" % (n, v) for n, v in views)), ""]
    header = ["field", "function", "n"] + [LABELS[r] for r in REPRESENTATIONS]
    body = []
    sizes = sorted({int(r["n"]) for r in rows})
    for field in sorted({r["field"] for r in rows}):
        for tf, tf_label in TFS:
            for n in sizes:
                cells = [field, tf, str(n)]
                for rep in REPRESENTATIONS:
                    best = best_psnr(rows, field, n, tf, rep)
                    if best is None:
                        cells.append("not run")
                        continue
                    got = []
                    for t in (30, 40, 50):
                        c = cheapest(rows, field, n, tf, [rep], t)
                        got.append(_mb(_num(c, "bytes")) if c else "—")
                    cells.append("%s MB (%.0f dB)" % (" / ".join(got), best))
                body.append(cells)
    lines += ["MB per step to reach 30 / 40 / 50 dB (best mean PSNR reached):", "",
              _table(header, body), ""]
    header = ["field", "function", "PSNR", "field bytes fit", "images fit (cheapest)",
              "crossover n", "field MB at 1024³ / 2048³ / 4096³", "images MB there"]
    body = []
    for a in analyse(rows):
        cross = a["crossover"]
        cross_text = ("%.0f" % cross) if cross else (
            "none: images never reach it" if not a["image_points"] else "—")
        field_proj = " / ".join(_mb(fit_at(a["field_fit"], n)) for n in PROJECTED) if a["field_fit"] else "—"
        image_proj = " / ".join(_mb(fit_at(a["image_fit"], n)) for n in PROJECTED) if a["image_fit"] else "—"
        images = ", ".join("%d: %s" % (n, who) for n, _, who in a["image_points"])
        body.append([a["field"], a["tf"], "%d dB" % a["threshold"], _fit_text(a["field_fit"]),
                     "%s (%s)" % (_fit_text(a["image_fit"]), images) if images else "—",
                     cross_text, field_proj, image_proj])
    lines += ["Fits: least squares of log bytes on log n over the measured sizes, per representation "
              "kind (the field's cheapest setting reaching the PSNR; for images, the representation "
              "cheapest at the largest size reaching it, over the sizes where it does, constant in "
              "n where that is one size); "
              "the crossover is where the fits meet, images cheaper above it. Projections are the "
              "fits evaluated beyond the measured sizes, not measurements.", "",
              _table(header, body), ""]
    return lines


def _table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)
