#!/usr/bin/python3
"""Plots of `beamcast bench accuracy`: plot_accuracy.py ACCURACY_CSV OUT_DIR.

Writes OUT_DIR/accuracy.png (rel_l1 against GPU time per frame, log-log, one
panel per representative scene) and OUT_DIR/accuracy_tables.png (rel_l1
against table size per layout, one panel per density scene). Exits 3 when
matplotlib is missing so the caller can say so and keep the CSV.
"""
import csv
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")  # no display on a headless machine
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter
except ImportError:
    print("plot_accuracy.py: matplotlib is not installed (apt install python3-matplotlib)",
          file=sys.stderr)
    sys.exit(3)

# Panels of accuracy.png, in order of preference: the paper's heaviest scene,
# the two hard densities/geometries, a many-beam scene, a smooth density.
REPRESENTATIVE = ["paper_10sets", "paper_1set", "thin_shell", "grazing_capsule", "beams_100",
                  "density_shell", "density_abe"]
MAX_PANELS = 6
# rel_l1 of exactly 0 (identical frames) cannot sit on a log axis.
FLOOR = 1e-9
LAYOUTS = ["uniform", "chord", "warped", "chord_warped"]


def read_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for key in ("gpu_ms", "rel_l1"):
            r[key] = float(r[key])
        r["table_size"] = int(r["table_size"]) if r["table_size"] else None
        r["samples"] = int(r["samples"]) if r["samples"] else None
    return rows


def grid(n):
    cols = min(3, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.2 * rows), squeeze=False)
    flat = [ax for row in axes for ax in row]
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]


def plain_log_x(ax):
    """Plain numbers on a log x axis; minor ticks labelled only when the axis
    spans less than about a decade (times often do), else they would crowd."""
    plain = FuncFormatter(lambda v, _: f"{v:g}")
    ax.xaxis.set_major_formatter(plain)
    lo, hi = ax.get_xlim()
    ax.xaxis.set_minor_formatter(plain if hi / lo < 12 else NullFormatter())
    ax.tick_params(axis="x", which="minor", labelsize=7)


def curves(rows):
    """(label, style, points) per curve of one scene, points sorted along the knob."""
    out = []
    for layout in LAYOUTS:
        for filt, style in (("hardware", "-o"), ("shader", "--s")):
            pts = sorted((r for r in rows if r["method"] == "table" and r["layout"] == layout
                          and r["filter"] == filt), key=lambda r: r["table_size"])
            if pts:
                label = f"table {layout}" + (" (shader filter)" if filt == "shader" else "")
                out.append((label, style, pts))
    for rule in ("midpoint", "simpson"):
        pts = sorted((r for r in rows if r["method"] == "march" and r["rule"] == rule),
                     key=lambda r: r["samples"])
        if pts:
            out.append((f"march {rule}", ":^", pts))
    closed = [r for r in rows if r["method"] == "closed_form"]
    if closed:
        out.append(("closed form", "*", closed))
    return out


def plot_error_vs_time(rows, scenes, path):
    fig, axes = grid(len(scenes))
    for ax, scene in zip(axes, scenes):
        for label, style, pts in curves([r for r in rows if r["scene"] == scene]):
            ax.plot([r["gpu_ms"] for r in pts], [max(r["rel_l1"], FLOOR) for r in pts], style,
                    label=label, markersize=4 if style != "*" else 12)
        ax.set_xscale("log")
        ax.set_yscale("log")
        plain_log_x(ax)
        ax.set_title(scene)
        ax.set_xlabel("GPU time per frame (ms)")
        ax.set_ylabel("relative L1 error (HDR)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Error against GPU time: tables grow in size, marches in N")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_error_vs_table(rows, scenes, path):
    fig, axes = grid(len(scenes))
    for ax, scene in zip(axes, scenes):
        for label, style, pts in curves([r for r in rows if r["scene"] == scene]):
            if not label.startswith("table"):
                continue
            ax.plot([r["table_size"] for r in pts], [max(r["rel_l1"], FLOOR) for r in pts], style,
                    label=label, markersize=4)
        ax.set_xscale("log", base=2)
        sizes = {r["table_size"] for r in rows if r["scene"] == scene and r["table_size"]}
        ax.set_xticks(sorted(sizes))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_yscale("log")
        ax.set_title(scene)
        ax.set_xlabel("table size (n x n)")
        ax.set_ylabel("relative L1 error (HDR)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Table error against table size, per layout")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    rows = read_rows(sys.argv[1])
    out_dir = sys.argv[2]
    present = list(dict.fromkeys(r["scene"] for r in rows))
    if not present:
        print("plot_accuracy.py: no rows to plot", file=sys.stderr)
        return 1
    rep = [s for s in REPRESENTATIVE if s in present][:MAX_PANELS] or present[:MAX_PANELS]
    plot_error_vs_time(rows, rep, os.path.join(out_dir, "accuracy.png"))
    # A quick run has no density scenes: its table curves are those of every scene.
    dens = [s for s in present if s.startswith("density_")]
    with_tables = [s for s in (dens or present) if any(r["scene"] == s and r["method"] == "table"
                                                       for r in rows)]
    if with_tables:
        plot_error_vs_table(rows, with_tables, os.path.join(out_dir, "accuracy_tables.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
