#!/usr/bin/python3
"""Plots `beamcast bench views` results: time per view against K, one K-camera
request versus K pipelined single-camera requests (end to end), and the
renderer alone batched versus one camera at a time.

Usage: plot_views.py views.csv views.png
"""
import csv
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    src, dst = sys.argv[1], sys.argv[2]
    e2e = defaultdict(list)
    gpu = defaultdict(list)
    with open(src, newline="") as f:
        for row in csv.DictReader(f):
            key = (row["mode"], int(row["k"]))
            e2e[key].append(float(row["e2e_ms"]))
            gpu[key].append(float(row["gpu_ms"]))
    modes = [
        ("one_request", "one K-camera request (e2e)", "C0", "-"),
        ("k_requests", "K pipelined requests (e2e)", "C1", "-"),
        ("renderer_batched", "renderer, multi-view batch", "C2", "--"),
        ("renderer_single", "renderer, one camera at a time", "C3", "--"),
    ]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for mode, label, color, style in modes:
        ks = sorted(k for (m, k) in e2e if m == mode)
        if not ks:
            continue
        per_view = [statistics.median(e2e[(mode, k)]) / k for k in ks]
        per_view_gpu = [statistics.median(gpu[(mode, k)]) / k for k in ks]
        axes[0].plot(ks, per_view, style, color=color, marker="o", label=label)
        axes[1].plot(ks, per_view_gpu, style, color=color, marker="o", label=label)
    for ax, title in zip(axes, ["wall time per view", "GPU (GL timestamps) time per view"]):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("views K")
        ax.set_ylabel("ms per view (median)")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        ax.set_ylim(bottom=0)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main()
