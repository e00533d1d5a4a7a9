#!/usr/bin/python3
"""Draws docs/scaling.png from dermis-bench's JSON (the "scaling" array of
`dermis-bench --only-scaling` or `--scaling`).

Usage: bench/plot_scaling.py BENCH.json [OUT.png]   (default OUT: docs/scaling.png)

One panel per series (placements, map size, triangles, joints): frame time in ms against the
variable, GPU height maps and CPU height maps, log-log axes where the variable spans decades, and a
dotted guide through the first GPU point
growing in proportion to the work (texels for the map size). Needs Debian's python3-matplotlib.
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# (series, JSON key, axis label, log axes, exponent of the "linear in the work" guide: map
# sides grow the work with side²)
SERIES = [
    ("placements", "placements", "placements (1024² map)", True, 1),
    ("map_size", "map_size", "height-map side (px)", True, 2),
    ("triangles", "triangles", "triangles", True, 1),
    ("joints", "joints", "joints", False, 0),
]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        data = json.load(f)
    rows = data["scaling"] if isinstance(data, dict) else data
    if not rows:
        sys.exit("plot_scaling: no scaling rows in " + sys.argv[1])
    out = sys.argv[2] if len(sys.argv) > 2 else "docs/scaling.png"
    fig, axes = plt.subplots(1, len(SERIES), figsize=(16, 4.2))
    for ax, (series, key, label, log, power) in zip(axes, SERIES):
        first = None
        for maps, style in (("gpu", "o-"), ("cpu", "s--")):
            pts = sorted((r[key], r["frame_ms"]) for r in rows
                         if r["series"] == series and r["heightmaps"] == maps)
            if not pts:
                continue
            xs, ys = zip(*pts)
            ax.plot(xs, ys, style, label=f"{maps.upper()} height maps")
            if maps == "gpu":
                first = pts[0]
        xs = sorted({r[key] for r in rows if r["series"] == series})
        if first and power:
            ax.plot(xs, [first[1] * (x / first[0]) ** power for x in xs], ":", color="grey",
                    label="∝ work, from the first GPU point")
        if log:
            ax.set_xscale("log")
            ax.set_yscale("log")
        else:
            ax.set_ylim(bottom=0)
        ax.set_xticks(xs)
        ax.set_xticklabels([f"{x:,}" for x in xs], fontsize=8)
        ax.minorticks_off()
        ax.set_xlabel(label)
        ax.set_ylabel("frame time (ms, 1024² frame)")
        ax.set_title(series.replace("_", " "))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    gl = data.get("gl") or {} if isinstance(data, dict) else {}
    fig.suptitle("dermis-bench --scaling: " + str(gl.get("gl_renderer", "")) + ", "
                 + str(data.get("hardware_threads", "?") if isinstance(data, dict) else "?")
                 + " hardware threads", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print("plot_scaling: wrote", out)


if __name__ == "__main__":
    main()
