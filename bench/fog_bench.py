#!/usr/bin/python3
"""Light scattered in a homogeneous medium: the seed's in-scattering estimate
against the beam radiance estimate, error against the path-traced reference
and GPU time, in one run (issue 15, item 3).
python3 bench/fog_bench.py --binary build/bin/beamcast --out DIR [--size N] [--spp N]

Scenes: examples/fog_stage.json (seed 001's stage: a spot light in fog,
sigma_t = 0.06, 50 000 photons), and the same with the medium five times
denser ("dense", sigma_t = 0.3), where a kernel's optical depth is no longer
small. Per scene: the reference (`beamcast render --reference`: the path
tracer with free flights and next-event estimation through the medium) twice
with different seeds, their mean taken as the reference and half their
relative L1 difference as its own noise; then the GPU frame for each
estimator ("seed": each photon at the ray's nearest point; "beam": its
kernel integrated along the visible ray) at 1/4, 1 and 4 times the scene's
photon count; and at the scene's count with the seed's photon level of
detail (gi.lod near 25, far 3, 16 groups: its fig 6.3 setting, photons near
the camera dropped; and near 0, far 20: its fig 6.4 setting, far photons
dropped); and, as the alternative to LOD, the volume kernels capped at 16
and 8 pixels on screen (medium.radius_pixels: nearer photons get smaller
kernels, none is dropped). Heterogeneous fog: examples/ground_fog.json
(a box of dense fog on the floor, seed fig 5.9) with the seed's S view-ray
segments (medium.segments: the regions' attenuation of each photon taken at
its segment's centre; 0 = exact) for both estimators, and "ground_fog_mesh",
the same layer bounded by a 12-triangle mesh instead of the box (the same
fog: its rows show what the shader's triangle loop costs; they use
ground_fog's reference). Per row: relative L1 against the reference (sum |gpu - ref| /
sum ref), the image mean's ratio to the reference's, the volume photons
stored, the GPU time of the frame and of the volume_photons pass (median of
the scene's copies of its camera). Writes DIR/fog.csv, DIR/fog.md and
DIR/fog.png and DIR/fog_segments.png.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def render(binary, scene, out_dir, extra):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    p = subprocess.run([binary, "render", path, "--json", "--hdr", "-o", out_dir] + extra,
                       capture_output=True, text=True, check=True)
    frames = json.loads(p.stdout)["frames"]
    w, h = frames[0]["width"], frames[0]["height"]
    img = np.fromfile(frames[0]["hdr_file"], dtype=np.float32).reshape(h, w, 3).astype(float)
    return img, frames


def pass_ms(frames, name):
    return statistics.median(
        sum(p["gpu_ms"] for p in f.get("passes", []) if p["name"] == name) for f in frames)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default="build/bin/beamcast")
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=2048, help="reference paths per pixel, per seed")
    ap.add_argument("--copies", type=int, default=5, help="cameras per GPU render (timing)")
    ap.add_argument("--scenes", default="fog_stage,dense,ground_fog,ground_fog_mesh",
                    help="comma-separated subset")
    ap.add_argument("--reuse-references", action="store_true",
                    help="take the references of an earlier run in DIR/work (same size and spp)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(ROOT, "examples", "fog_stage.json")) as f:
        base = json.load(f)
    base["cameras"] = [dict(base["cameras"][0], width=args.size, height=args.size)]
    dense = json.loads(json.dumps(base))
    dense["medium"]["sigma_s"] *= 5
    dense["medium"]["sigma_a"] *= 5
    with open(os.path.join(ROOT, "examples", "ground_fog.json")) as f:
        ground = json.load(f)
    ground["cameras"] = [dict(ground["cameras"][0], width=args.size, height=args.size)]
    ground_mesh = json.loads(json.dumps(ground))
    box = ground_mesh["media"][0]
    lo, hi = box.pop("min"), box.pop("max")
    box["type"] = "mesh"
    box["vertices"] = [[(hi if i & (1 << k) else lo)[k] for k in range(3)] for i in range(8)]
    box["triangles"] = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                        [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]
    rows = []
    work = os.path.join(args.out, "work")
    wanted = args.scenes.split(",")
    scenes = (("fog_stage", base), ("dense", dense), ("ground_fog", ground),
              ("ground_fog_mesh", ground_mesh))
    for name, scene in scenes:
        if name not in wanted:
            continue
        refs = []
        for seed in (1, 2):
            ref_name = "ground_fog" if name == "ground_fog_mesh" else name
            ref_dir = os.path.join(work, "%s_ref%d" % (ref_name, seed))
            cached = os.path.join(ref_dir, "view.rgb32f")
            if (args.reuse_references or ref_name != name) and os.path.exists(cached):
                size = args.size
                refs.append(np.fromfile(cached, dtype=np.float32).reshape(size, size, 3)
                            .astype(float))
                continue
            img, _ = render(args.binary, scene, ref_dir,
                            ["--reference", "--spp", str(args.spp), "--seed", str(seed)])
            refs.append(img)
        ref = 0.5 * (refs[0] + refs[1])
        noise = 0.5 * float(np.abs(refs[0] - refs[1]).sum() / ref.sum())
        print("%s: reference noise (rel L1 of the mean of two) %.3f" % (name, noise), flush=True)
        photons = scene["gi"]["photons"]
        if name.startswith("ground_fog"):
            segments = (0, 1, 2, 4, 8, 16, 32) if name == "ground_fog" else (0,)
            runs = [(est, photons, None, 0, sg) for est in ("seed", "beam") for sg in segments]
        else:
            runs = [(est, n, None, 0, 0) for est in ("seed", "beam")
                    for n in (photons // 4, photons, photons * 4)]
            runs += [("beam", photons, (25.0, 3.0, 16), 0, 0),
                     ("beam", photons, (0.0, 20.0, 16), 0, 0)]
            runs += [("beam", photons, None, px, 0) for px in (16, 8)]
        for est, n, lod, radius_px, segments in runs:
            s = json.loads(json.dumps(scene))
            s["medium"]["estimator"] = est
            if segments:
                s["medium"]["segments"] = segments
            s["gi"]["photons"] = n
            if lod:
                s["gi"]["lod"] = {"near": lod[0], "far": lod[1], "groups": lod[2]}
            if radius_px:
                s["medium"]["radius_pixels"] = radius_px
            s["cameras"] = [dict(s["cameras"][0], name="c%d" % i) for i in range(args.copies)]
            img, frames = render(args.binary, s, os.path.join(work, "gpu"), [])
            row = {"scene": name, "estimator": est, "photons": n, "segments": segments,
                   "lod": ("n=%g f=%g A=%d" % lod if lod else
                           "radius <= %d px" % radius_px if radius_px else "off"),
                   "volume_photons": frames[0].get("photons", {}).get("volume", 0),
                   "rel_l1": float(np.abs(img - ref).sum() / ref.sum()),
                   "mean_ratio": float(img.mean() / ref.mean()),
                   "reference_noise": noise,
                   "frame_ms": statistics.median(f["gpu_ms"] for f in frames),
                   "volume_ms": pass_ms(frames, "volume_photons")}
            rows.append(row)
            print("%-9s %-4s %7d photons (%6d volume) LOD %-16s S %2d: rel L1 %.3f  mean %.3f  "
                  "frame %.0f ms (volume pass %.0f ms)" %
                  (name, est, n, row["volume_photons"], row["lod"], segments, row["rel_l1"],
                   row["mean_ratio"], row["frame_ms"], row["volume_ms"]), flush=True)
    with open(os.path.join(args.out, "fog.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(args.out, "fog.md"), "w") as f:
        f.write("| scene | estimator | photons | LOD or kernel cap | segments S | volume photons | "
                "rel L1 | mean / reference | frame ms | frames/s | volume pass ms |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %d | %s | %s | %d | %.3f | %.3f | %.0f | %.2f | %.0f |\n" %
                    (r["scene"], r["estimator"], r["photons"], r["lod"],
                     r["segments"] or "exact", r["volume_photons"],
                     r["rel_l1"], r["mean_ratio"], r["frame_ms"], 1000.0 / r["frame_ms"],
                     r["volume_ms"]))
        for name in sorted({r["scene"] for r in rows}):
            noise = next(r["reference_noise"] for r in rows if r["scene"] == name)
            f.write("\nReference noise (%s): %.3f of the rel L1 above.\n" % (name, noise))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    names = [n for n in ("fog_stage", "dense") if any(r["scene"] == n for r in rows)]
    if names:
        fig, axes = plt.subplots(1, len(names), figsize=(5 * len(names), 4), squeeze=False)
        for ax, name in zip(axes[0], names):
            for est, mark in (("seed", "s--"), ("beam", "o-")):
                sel = [r for r in rows if r["scene"] == name and r["estimator"] == est and
                       r["lod"] == "off"]
                ax.loglog([r["photons"] for r in sel], [r["rel_l1"] for r in sel], mark,
                          label=est)
            noise = next(r["reference_noise"] for r in rows if r["scene"] == name)
            ax.axhline(noise, color="grey", ls=":", label="reference's own noise")
            ax.set_title(name, fontsize=9)
            ax.set_xlabel("photons emitted")
            ax.set_ylabel("relative L1 against the path tracer")
            ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "fog.png"), dpi=110)
    ground = [r for r in rows if r["scene"] == "ground_fog"]
    if ground:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for est, mark, color in (("seed", "s--", "C0"), ("beam", "o-", "C1")):
            sel = [r for r in ground if r["estimator"] == est and r["segments"]]
            ax.semilogx([r["segments"] for r in sel], [r["rel_l1"] for r in sel], mark,
                        color=color, base=2, label="%s, S segments" % est)
            for r in ground:
                if r["estimator"] == est and not r["segments"]:
                    ax.axhline(r["rel_l1"], color=color, ls=":", label="%s, exact" % est)
        ax.axhline(ground[0]["reference_noise"], color="grey", ls="-.",
                   label="reference's own noise")
        ax.set_xlabel("view-ray segments S (medium.segments)")
        ax.set_ylabel("relative L1 against the path tracer")
        ax.set_title("ground_fog: the seed's S segments", fontsize=9)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "fog_segments.png"), dpi=110)

if __name__ == "__main__":
    main()
