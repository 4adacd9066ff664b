#!/usr/bin/python3
"""The before/after picture of docs/stability.md (the paper's fig 3.4 case).

Input: the PNGs that `BEAMCAST_DOC_IMAGES=DIR beamcast_stability_tests
--gtest_filter=Stability.NearParallelThroughEnergyPaperVersusOurs` writes.
Output: one side-by-side figure, full view and a zoom on the shell's rim.
Usage: /usr/bin/python3 scripts/plot_streaks.py DIR docs/img/streaks.png
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402


def main(src, out):
    panels = [
        ("streak_paper", "paper's form"),
        ("streak_ours", "ours"),
        ("streak_reference", "CPU reference (double)"),
        ("streak_paper_error50x", "|paper - reference| x50"),
        ("streak_ours_error50x", "|ours - reference| x50"),
    ]
    fig, axes = plt.subplots(2, len(panels), figsize=(3.2 * len(panels), 6.6))
    for col, (name, title) in enumerate(panels):
        img = mpimg.imread(f"{src}/{name}.png")
        h, w = img.shape[:2]
        axes[0, col].imshow(img, interpolation="nearest")
        axes[0, col].set_title(title, fontsize=10)
        # Zoom: the upper rim of the shell, where the streaks are.
        axes[1, col].imshow(img[int(0.10 * h):int(0.32 * h), int(0.35 * w):int(0.65 * w)],
                            interpolation="nearest")
        for row in range(2):
            axes[row, col].axis("off")
    fig.suptitle("shell capsule seen at 1e-4 rad to its axis (orthographic, default table)",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=80)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
