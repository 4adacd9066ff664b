#!/usr/bin/python3
"""Plots beamcast_bench_video's CSV (--csv): bytes a second against PSNR of
the displayed frames, JPEG at its qualities and VP8/VP9/AV1 at their
bitrates, one panel per scene and size (docs/performance.md, "Video preview").
Rows of a codec at more than one speed (the CSV's last column) in one panel
are plotted per speed.

Usage: plot_video.py video.csv video.png
"""
import csv
import math
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FIELDS = ["scene", "size", "path", "setting", "bytes_per_s", "psnr", "ssim",
          "encode_ms", "decode_ms", "raw_psnr", "raw_ssim", "encode_wall_ms", "threads", "speed",
          "bits", "frames_8bit", "bands"]


def main():
    src, dst = sys.argv[1], sys.argv[2]
    panels = defaultdict(lambda: defaultdict(list))
    ceiling = {}
    settings = defaultdict(lambda: defaultdict(list))
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f, fieldnames=FIELDS))
    speeds = defaultdict(set)
    for row in rows:
        speeds[(row["scene"], row["size"], row["path"])].add(row["speed"])
    for row in rows:
        key = (row["scene"], row["size"])
        path = row["path"]
        if len(speeds[key + (path,)]) > 1 and row["speed"]:
            path += f" s{row['speed']}"
        panels[key][path].append((float(row["bytes_per_s"]), float(row["psnr"])))
        settings[key][path].append(float(row["setting"]))
        ceiling[key] = float(row["raw_psnr"])
    codecs = sorted({p for k in panels for p in panels[k] if p != "jpeg"})
    keys = sorted(panels)
    cols = min(3, len(keys))
    rows_n = math.ceil(len(keys) / cols)
    fig, grid = plt.subplots(rows_n, cols, figsize=(4.2 * cols, 3.6 * rows_n), squeeze=False)
    axes = [[ax for row in grid for ax in row]]
    for ax in axes[0][len(keys):]:
        ax.set_visible(False)
    styles = {"jpeg": ("C0", "o", "JPEG (q50-92)"), "vp8": ("C1", "s", "VP8"),
              "vp9": ("C2", "^", "VP9"), "av1": ("C3", "D", "AV1"),
              "av1-before": ("0.6", "d", "AV1, stop 52's encoder"),
              "av1-8bit": ("C3", "D", "AV1, 8 bits"), "av1-10bit": ("C4", "P", "AV1, 10 bits"),
              "av1-1picture": ("C3", "D", "AV1, 8 bits, one picture (libaom at speed 7)"),
              "av1-bands": ("C4", "P", "AV1, 10 bits, 2 bands (speed 6)")}
    for ax, key in zip(axes[0], keys):
        for i, (path, pts) in enumerate(sorted(panels[key].items())):
            pts.sort()
            base = path.split(" ")[0]
            color, marker, label = styles.get(base, (f"C{4 + i}", "x", base))
            label += path[len(base):]
            ax.plot([b * 8 / 1e6 for b, _ in pts], [p for _, p in pts], marker=marker,
                    color=color, label=label)
        ax.axhline(ceiling[key], color="0.5", ls=":", lw=1, label="level without compression")
        ax.set_xscale("log")
        ax.set_xlabel("Mbit/s at 30 frames/s")
        ax.set_ylabel("PSNR dB vs full accuracy")
        ax.set_title(f"{key[0]} {key[1]}", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    # Bytes at equal PSNR: each JPEG point against the video curve,
    # interpolated linearly in PSNR against log(bytes); none where the
    # codec's curve does not reach the JPEG point's PSNR.
    print("| scene | size | JPEG | JPEG PSNR | JPEG KiB/s | " +
          " | ".join(f"{c.upper()} KiB/s (ratio)" for c in codecs) + " |")
    print("|---|---|---|---|---|" + "---|" * len(codecs))
    for key in keys:
        jpeg = sorted(zip(panels[key]["jpeg"], settings[key]["jpeg"]))
        cells = []
        for (jb, jp), q in jpeg:
            row = [key[0], key[1], f"q{q:g}", f"{jp:.2f}", f"{jb / 1024:.0f}"]
            for codec in codecs:
                pts = sorted(panels[key].get(codec, []))
                found = None
                for (b0, p0), (b1, p1) in zip(pts, pts[1:]):
                    if p0 <= jp <= p1 and p1 > p0:
                        f = (jp - p0) / (p1 - p0)
                        found = math.exp(math.log(b0) + f * (math.log(b1) - math.log(b0)))
                        break
                if found is None and pts and pts[0][1] >= jp:
                    found = pts[0][0]
                row.append("not reached" if found is None
                           else f"{found / 1024:.0f} ({found / jb:.2f})")
            cells.append("| " + " | ".join(row) + " |")
        print("\n".join(cells))


if __name__ == "__main__":
    main()
