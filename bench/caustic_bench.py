#!/usr/bin/python3
"""The caustic under the glass sphere (issue 14): its error against the
path-traced reference as the caustic photon count grows.
python3 bench/caustic_bench.py --out DIR [--quick].

Renders examples/cornell_caustic.json (a glass and a mirror sphere in the
Cornell box) with `beamcast render`: the reference (`--reference`, twice with
different seeds, so its own noise is measured as in gi_bench.py), then the
GPU frame for caustic photon counts 1e3 ... 1e6 (global map at its default,
1e5). The caustic region is the floor the camera sees within 1.5 radii
(horizontally) of the point where the glass sphere touches it: where the
light focused by the sphere lands. Per count: photon tracing time, GPU time
per frame (maps cached), the relative L1 error over the caustic region and
over the image's diffuse surfaces (the spheres left out), over the mirror
and over the glass sphere's pixels (what the "specular" pass shows: the
CPU follows their rays to the photon-lit surfaces they reach), and the
log-log slope of the region's error against the caustic photon count. Writes DIR/caustic.csv,
DIR/caustic.md, DIR/caustic.png (error against count) and
DIR/caustic_crop.png (the region: reference, 1e4, 1e5, 1e6 photons).
"""
import argparse
import csv
import json
import os
import statistics
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gi_bench import ROOT, camera_rays, label_pixels, load_hdr, rel_l1, run_render  # noqa: E402


def sphere_hits(o, d, spheres):
    """Per pixel: distance to the nearest sphere along the ray (inf: none)."""
    best = np.full(d.shape[:2], np.inf)
    for s in spheres:
        c = np.array(s["center"], float)
        oc = o - c
        b = d @ oc
        disc = b * b - (oc @ oc - s["radius"] ** 2)
        with np.errstate(invalid="ignore"):
            t = -b - np.sqrt(disc)
        best = np.where((disc > 0) & (t > 0) & (t < best), t, best)
    return best


def regions(scene, cam):
    """(caustic region, diffuse pixels, {material: its sphere's pixels}) as
    boolean masks, rows top-down."""
    o, d = camera_rays(cam)
    label = label_pixels(scene, cam)
    spheres = [s for s in scene["occluders"] if s["type"] == "sphere"]
    t_sphere = sphere_hits(o, d, spheres)
    # The floor is the first quad (scripts/make_examples.py); its plane y = 0.
    with np.errstate(divide="ignore", invalid="ignore"):
        t_floor = -o[1] / d[..., 1]
    floor = (label == 0) & (t_floor < t_sphere)
    glass = next(s for s in spheres if s.get("material", {}).get("type") == "glass")
    p = o + t_floor[..., None] * d
    c = np.array(glass["center"], float)
    near = np.hypot(p[..., 0] - c[0], p[..., 2] - c[2]) < 1.5 * glass["radius"]
    # Spheres stand inside the room: a ray that meets one meets it first.
    diffuse = (label >= 0) & ~np.isfinite(t_sphere)
    by_material = {}
    for sph in spheres:
        kind = sph.get("material", {}).get("type", "diffuse")
        by_material[kind] = np.isfinite(sphere_hits(o, d, [sph])) & (sphere_hits(o, d, [sph]) <= t_sphere)
    return floor & near, diffuse, by_material


def tone(hdr, exposure):
    x = 1 - np.exp(-exposure * np.maximum(hdr, 0))
    return np.clip(np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055), 0, 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "cornell_caustic.json"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true", help="128x128, reference 2 x 64 spp, up to 1e5")
    ap.add_argument("--size", type=int, help="frame size (default 256, 128 with --quick)")
    ap.add_argument("--spp", type=int, help="reference samples per pixel (default 1024, 64 quick)")
    ap.add_argument("--views", type=int, default=2, help="camera copies per GPU render")
    a = ap.parse_args()
    size = a.size or (128 if a.quick else 256)
    spp = a.spp or (64 if a.quick else 1024)
    os.makedirs(a.out, exist_ok=True)
    with open(a.scene) as f:
        base = json.load(f)
    cam = dict(base["cameras"][0], width=size, height=size)
    base["cameras"] = [cam]
    exposure = base.get("output", {}).get("exposure", 1.0)
    region, diffuse, spheres = regions(base, cam)

    refs, walls = [], []
    for seed in (1, 2):
        summary, wall = run_render(a.binary, base, os.path.join(a.out, f"ref{seed}"),
                                   ["--reference", "--spp", str(spp), "--seed", str(seed)])
        refs.append(load_hdr(summary["frames"][0]))
        walls.append(wall)
    ref = 0.5 * (refs[0] + refs[1])
    noise_region = rel_l1(refs[0], refs[1], region) / 2
    noise_diffuse = rel_l1(refs[0], refs[1], diffuse) / 2
    noise_mirror = rel_l1(refs[0], refs[1], spheres["mirror"]) / 2
    noise_glass = rel_l1(refs[0], refs[1], spheres["glass"]) / 2

    counts = [1000, 10000, 100000] if a.quick else [1000, 3000, 10000, 30000, 100000, 300000, 1000000]
    # Then the specular pass's rays per pixel (K x K; the default, 2, is in
    # the count rows) at 1e5 caustic photons.
    runs = [(n, 2) for n in counts] + [(100000, k) for k in (1, 4)]
    rows, crops = [], {}
    for n, k in runs:
        s = dict(base, gi=dict(base.get("gi", {}), caustic_photons=n, specular_samples=k))
        s["cameras"] = [dict(cam, name=f"v{i}", position=[cam["position"][0] + 0.01 * i] +
                             cam["position"][1:]) for i in range(a.views)]
        summary, _ = run_render(a.binary, s, os.path.join(a.out, "gpu"), [])
        frames = summary["frames"]
        img = load_hdr(frames[0])
        row = {"caustic_photons": n, "specular_samples": k, "stored": frames[0]["photons"]["count"],
               "trace_ms": round(frames[0]["photons"]["trace_ms"], 1),
               "gpu_ms": round(statistics.median(f["gpu_ms"] for f in frames), 1),
               "rel_l1_caustic": round(rel_l1(img, ref, region), 4),
               "rel_l1_diffuse": round(rel_l1(img, ref, diffuse), 4),
               "rel_l1_mirror": round(rel_l1(img, ref, spheres["mirror"]), 4),
               "rel_l1_glass": round(rel_l1(img, ref, spheres["glass"]), 4),
               "wall_ms": round(statistics.median(f["wall_ms"] for f in frames), 1),
               "caustic_ratio": round(float(img[region].sum() / ref[region].sum()), 4)}
        rows.append(row)
        print(json.dumps(row), flush=True)
        if n in (10000, 100000, 1000000) and k == 2:
            crops[n] = img

    with open(os.path.join(a.out, "caustic.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    count_rows = [r for r in rows if r["specular_samples"] == 2]
    x = np.log10([r["caustic_photons"] for r in count_rows])
    y = np.log10([r["rel_l1_caustic"] for r in count_rows])
    slope = float(np.polyfit(x, y, 1)[0])
    with open(os.path.join(a.out, "caustic.md"), "w") as f:
        f.write(f"# The glass sphere's caustic against the path tracer ({size}x{size})\n\n")
        f.write(f"Reference: 2 x {spp} spp ({walls[0]:.0f} + {walls[1]:.0f} s); its own noise "
                f"(rel. L1) over the caustic region {noise_region:.4f}, over the diffuse "
                f"surfaces {noise_diffuse:.4f}, over the mirror sphere {noise_mirror:.4f}, over the "
                f"glass sphere {noise_glass:.4f}. Caustic region: {int(region.sum())} pixels; mirror "
                f"{int(spheres['mirror'].sum())}, glass {int(spheres['glass'].sum())}.\n")
        f.write(f"Log-log slope of the region's error against caustic photons: {slope:.2f}.\n\n")
        cols = list(rows[0].keys())
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r[c]) for c in cols) + " |\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5.5, 4))
        ax.loglog([r["caustic_photons"] for r in count_rows], [r["rel_l1_caustic"] for r in count_rows],
                  "o-", label=f"caustic region (slope {slope:.2f})")
        ax.loglog([r["caustic_photons"] for r in count_rows], [r["rel_l1_diffuse"] for r in count_rows],
                  "s--", label="all diffuse surfaces")
        ax.axhline(noise_region, color="grey", lw=0.8, label="reference noise (region)")
        ax.set_xlabel("caustic photons emitted")
        ax.set_ylabel("relative L1 error")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "caustic.png"), dpi=110)
        # The region's bounding box, with a margin, side by side.
        ys, xs = np.nonzero(region)
        y0, y1 = max(ys.min() - 8, 0), min(ys.max() + 9, size)
        x0, x1 = max(xs.min() - 8, 0), min(xs.max() + 9, size)
        panels = [("reference", ref)] + [(f"{n:.0e} caustic photons", im) for n, im in crops.items()]
        fig, ax = plt.subplots(1, len(panels), figsize=(3 * len(panels), 3))
        for axis, (title, im) in zip(ax, panels):
            axis.imshow(tone(im[y0:y1, x0:x1], exposure), interpolation="nearest")
            axis.set_title(title, fontsize=9)
            axis.axis("off")
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "caustic_crop.png"), dpi=90)
    except ImportError:
        print("matplotlib missing: no plots", file=sys.stderr)
    print(f"slope {slope:.3f}; wrote {a.out}/caustic.csv, caustic.md")


if __name__ == "__main__":
    main()
