#!/usr/bin/python3
"""Beams seen through a homogeneous medium: error against the CPU reference
versus GPU time, per rule and step, across sigma_t r (issue 15, item 4).
python3 bench/medium_bench.py --binary build/bin/beamcast --out DIR [--size N]

The scene: three unit spheres (quadratic, shell, abe densities) and a
gaussian capsule of radius 0.8 seen obliquely, a sphere occluder cutting
into the capsule (the scene of tests/gl/test_medium.cpp), medium
sigma_a = sigma_t r for sigma_t r in 1e-3 ... 10. Per sigma_t r: the
reference (`beamcast render --reference`: f e^(-sigma_t t) integrated along
each ray in double), then the GPU frame for each rule: "gauss2" (the
default) at steps 2, 1 and 0.5, "midpoint" at step 1 and in one piece (step
8). Per row: relative L1 over the image (sum |gpu - ref| / sum ref), the
worst pixel's relative error among pixels with at least 1% of the image's
brightest reference value, and the GPU time per frame (median over the
scene's copies of the camera). The first row, without a medium, is the
table's own error. Also the rule's own error in double (`beamcast bench
medium-rule`: exact moments, no table, whole chords and pieces of them, per
density). Writes DIR/medium.csv, DIR/medium.md, DIR/medium_rule.csv and
DIR/medium.png.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess

import numpy as np

SIGMA_R = [1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0]
VARIANTS = [("gauss2", 2.0), ("gauss2", 1.0), ("gauss2", 0.5), ("midpoint", 1.0), ("midpoint", 8.0)]


def scene(size, copies, medium):
    cam = {"position": [0.5, 1.0, 7.0], "target": [0, 0, 0], "width": size, "height": size}
    s = {"beams": [
        {"type": "sphere", "center": [-2.4, 1.2, 0], "radius": 1.0, "density": "quadratic"},
        {"type": "sphere", "center": [0, 1.2, 0], "radius": 1.0, "density": "shell"},
        {"type": "sphere", "center": [2.4, 1.2, 0], "radius": 1.0, "density": "abe"},
        {"type": "capsule", "p0": [-2.5, -1.4, -1.5], "p1": [2.5, -1.2, 1.0], "radius": 0.8,
         "density": "gaussian"}],
        "occluders": [{"type": "sphere", "center": [1.5, -1.3, 0.5], "radius": 0.6}],
        "cameras": [dict(cam, name="c%d" % i) for i in range(copies)]}
    if medium:
        s["medium"] = medium
    return s


def render(binary, sc, out_dir, extra):
    """The first frame and the median GPU time of the scene's frames (its camera copies: the
    median drops the first frame's shader compilation)."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.json")
    with open(path, "w") as f:
        json.dump(sc, f)
    p = subprocess.run([binary, "render", path, "--json", "--hdr", "-o", out_dir] + extra,
                       capture_output=True, text=True, check=True)
    summary = json.loads(p.stdout)
    frames = summary["frames"]
    w, h = frames[0]["width"], frames[0]["height"]
    img = np.fromfile(frames[0]["hdr_file"], dtype=np.float32).reshape(h, w, 3).astype(float)
    gpu = statistics.median(f.get("gpu_ms", 0.0) for f in frames)
    return img, gpu


def errors(img, ref):
    diff = np.abs(img - ref).sum(axis=-1)
    tot = ref.sum(axis=-1)
    l1 = float(diff.sum() / tot.sum()) if tot.sum() > 0 else float("nan")
    mask = tot >= 0.01 * tot.max()
    worst = float((diff[mask] / tot[mask]).max()) if mask.any() else float("nan")
    return l1, worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default="build/bin/beamcast")
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--copies", type=int, default=5, help="cameras per GPU render (timing)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    p = subprocess.run([args.binary, "bench", "medium-rule"], capture_output=True, text=True,
                       check=True)
    with open(os.path.join(args.out, "medium_rule.csv"), "w") as f:
        f.write(p.stdout)
    rule_rows = list(csv.DictReader(p.stdout.splitlines()))
    rows = []
    work = os.path.join(args.out, "work")
    ref, _ = render(args.binary, scene(args.size, 1, None), os.path.join(work, "ref0"),
                    ["--reference"])
    img, gpu = render(args.binary, scene(args.size, args.copies, None), os.path.join(work, "gpu0"),
                      [])
    l1, worst = errors(img, ref)
    rows.append({"sigma_r": 0, "rule": "none", "step": "", "rel_l1": l1, "worst_pixel": worst,
                 "gpu_ms": gpu})
    for sr in SIGMA_R:
        medium = {"sigma_a": sr}
        ref, _ = render(args.binary, scene(args.size, 1, medium), os.path.join(work, "ref"),
                        ["--reference"])
        for rule, step in VARIANTS:
            m = dict(medium, beam_rule=rule, beam_step=step)
            img, gpu = render(args.binary, scene(args.size, args.copies, m),
                              os.path.join(work, "gpu"), [])
            l1, worst = errors(img, ref)
            rows.append({"sigma_r": sr, "rule": rule, "step": step, "rel_l1": l1,
                         "worst_pixel": worst, "gpu_ms": gpu})
            print("sigma_t r %-6g %-8s step %-4g  rel L1 %.2e  worst pixel %.2e  gpu %.2f ms" %
                  (sr, rule, step, l1, worst, gpu), flush=True)
    with open(os.path.join(args.out, "medium.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(args.out, "medium.md"), "w") as f:
        f.write("| sigma_t r | rule | step | rel L1 | worst pixel | GPU ms/frame |\n")
        f.write("|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %s | %.2e | %.2e | %.2f |\n" %
                    (r["sigma_r"] or "no medium", r["rule"], r["step"], r["rel_l1"],
                     r["worst_pixel"], r["gpu_ms"]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, (r0, a, b) = plt.subplots(1, 3, figsize=(15, 4.2))
    for i, (rule, step) in enumerate(VARIANTS):
        label = "%s, step %g" % (rule, step) if step < 8 else "%s, one piece" % rule
        color = "C%d" % i
        mine = [r for r in rule_rows if r["rule"] == rule and float(r["step"]) == step]
        xs = sorted({float(r["sigma_r"]) for r in mine})
        worst = [max(float(r["worst_rel_error"]) for r in mine if float(r["sigma_r"]) == x)
                 for x in xs]
        r0.loglog(xs, worst, "o-", color=color, label=label)
        sel = [r for r in rows if r["rule"] == rule and r["step"] == step]
        a.loglog([r["sigma_r"] for r in sel], [r["rel_l1"] for r in sel], "o-", color=color,
                 label=label)
        one = [r for r in sel if r["sigma_r"] == 1.0]
        b.semilogy([one[0]["gpu_ms"]], [one[0]["rel_l1"]], "o", color=color, label=label)
    base = rows[0]
    r0.axhline(1e-3, color="grey", ls=":", label="1e-3 (the issue's bound)")
    r0.set_xlabel("sigma_t r")
    r0.set_ylabel("worst relative error of a piece (double, all densities)")
    r0.set_title("the rule alone", fontsize=9)
    r0.legend(fontsize=7)
    a.axhline(base["rel_l1"], color="k", ls="--", lw=0.8, label="no medium (the table's error)")
    a.set_xlabel("sigma_t r")
    a.set_ylabel("relative L1 of the GPU image")
    a.set_title("GPU image against the reference (%d^2)" % args.size, fontsize=9)
    a.legend(fontsize=7)
    b.semilogy([base["gpu_ms"]], [base["rel_l1"]], "ks", label="no medium")
    b.set_xlabel("GPU ms per frame (%d^2)" % args.size)
    b.set_ylabel("relative L1 at sigma_t r = 1")
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "medium.png"), dpi=110)


if __name__ == "__main__":
    main()
