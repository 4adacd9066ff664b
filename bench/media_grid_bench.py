#!/usr/bin/python3
"""Media without splats (issue 39, item 5): the volume photons' light by the
grid estimate (medium.estimator "grid") against the splats, error against
the path tracer and frame time, an old build against a new one, interleaved.
python3 bench/media_grid_bench.py --old OLD/beamcast --new NEW/beamcast --out DIR

Scenes: examples/fog_stage.json (the seed's stage, 50 000 photons),
ground_fog.json (its dense layer of fog on the floor) and beam_fog.json
(emitting beams in the fog), at the examples' settings but for the size.

Error (--error-size, default 128): per scene the path tracer twice with
different seeds (`beamcast render --reference`, --spp paths a pixel each;
--refs DIR keeps them between runs), their mean the reference and half
their relative L1 difference its own noise; then relative L1 (sum |gpu -
ref| / sum ref) and the mean's ratio for: the old build's default (beam
splats), the new build's default (the grid), the new build's splats
("beam"), and the grid's knobs: gi.lod at the seed's two settings (fig 6.3:
near 25, far 3; fig 6.4: near 0, far 20) and medium.radius (the grid's cell
is 1.6 radii) at 0.5, 0.75, 1.5 and 2 times the default.

Time (--time-size, default 512): every configuration above rendered
--rounds times, old and new interleaved round by round, --copies cameras a
render; per configuration the median over rounds of the median frame's GPU
time (`gpu_ms`: timer queries around the passes; on llvmpipe the
rasterizer's CPU work) and of its volume pass (volume_photons or
volume_grid). Writes DIR/media_grid.csv and DIR/media_grid.md.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SCENES = ("fog_stage", "ground_fog", "beam_fog")


def scene_at(name, size):
    with open(os.path.join(ROOT, "examples", name + ".json")) as f:
        s = json.load(f)
    s["cameras"] = [dict(s["cameras"][0], width=size, height=size)]
    return s


def render(binary, scene, out_dir, extra=()):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    p = subprocess.run([binary, "render", path, "--json", "--hdr", "-o", out_dir] + list(extra),
                       capture_output=True, text=True, check=True)
    frames = json.loads(p.stdout)["frames"]
    w, h = frames[0]["width"], frames[0]["height"]
    img = np.fromfile(frames[0]["hdr_file"], dtype=np.float32).reshape(h, w, 3).astype(float)
    return img, frames


def volume_ms(frame):
    return sum(p["gpu_ms"] for p in frame.get("passes", [])
               if p["name"] in ("volume_photons", "volume_grid"))


# (label, build, change to the scene): the configurations of each scene.
def configs(scene):
    out = [("old default (beam splats)", "old", {}),
           ("new default (grid)", "new", {}),
           ("new, estimator beam (splats)", "new", {"estimator": "beam"})]
    for near, far in ((25.0, 3.0), (0.0, 20.0)):
        out.append(("new grid, gi.lod n=%g f=%g" % (near, far), "new",
                    {"lod": {"near": near, "far": far, "groups": 16}}))
    for f in (0.5, 0.75, 1.5, 2.0):
        out.append(("new grid, radius x%g" % f, "new", {"radius_factor": f}))
    return out


def apply(scene, change, radius):
    s = json.loads(json.dumps(scene))
    if "estimator" in change:
        s["medium"]["estimator"] = change["estimator"]
    if "lod" in change:
        s["gi"]["lod"] = change["lod"]
    if "radius_factor" in change:
        s["medium"]["radius"] = radius * change["radius_factor"]
    return s


def default_radius(scene, volume_photons):
    """gi/photon_map.cpp default_volume_radius: ~50 photons per kernel sphere
    spread evenly through the occluders' and lights' box."""
    pts = []
    for o in scene.get("occluders", []):
        if o["type"] == "quad":
            c, u, v = (np.array(o[k], float) for k in ("corner", "edge_u", "edge_v"))
            pts += [c, c + u, c + v, c + u + v]
        elif o["type"] == "sphere":
            pts += [np.array(o["center"]) - o["radius"], np.array(o["center"]) + o["radius"]]
        elif o["type"] == "box":
            h = 0.5 * np.linalg.norm(o["size"])
            pts += [np.array(o["center"]) - h, np.array(o["center"]) + h]
    for light in scene.get("lights", []):
        pts.append(np.array(light["position"], float))
    pts = np.array(pts)
    s = pts.max(axis=0) - pts.min(axis=0)
    m = 0.1 * s.max()
    vol = np.prod(np.maximum(s, m))
    return (3.0 * 50.0 * vol / (4.0 * np.pi * volume_photons)) ** (1.0 / 3.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", required=True)
    ap.add_argument("--new", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--refs", help="reference directory (default DIR/refs)")
    ap.add_argument("--error-size", type=int, default=128)
    ap.add_argument("--time-size", type=int, default=512)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--copies", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    refs_dir = args.refs or os.path.join(args.out, "refs")
    work = os.path.join(args.out, "work")
    bins = {"old": args.old, "new": args.new}
    rows = []
    for name in args.scenes.split(","):
        small = scene_at(name, args.error_size)
        refs = []
        for seed in (1, 2):
            d = os.path.join(refs_dir, "%s_%d" % (name, seed))
            cached = os.path.join(d, "view.rgb32f")
            if os.path.exists(cached):
                n = args.error_size
                refs.append(np.fromfile(cached, dtype=np.float32).reshape(n, n, 3).astype(float))
            else:
                refs.append(render(args.new, small, d,
                                   ["--reference", "--spp", str(args.spp), "--seed",
                                    str(seed)])[0])
        ref = 0.5 * (refs[0] + refs[1])
        noise = 0.5 * float(np.abs(refs[0] - refs[1]).sum() / ref.sum())
        _, probe = render(args.new, small, os.path.join(work, "probe"))
        vp = probe[0].get("photons", {}).get("volume", 1)
        radius = default_radius(small, max(vp, 1))
        scene_rows = []
        for label, build, change in configs(small):
            img, _ = render(bins[build], apply(small, change, radius), os.path.join(work, "err"))
            scene_rows.append({"scene": name, "config": label, "build": build,
                               "rel_l1": float(np.abs(img - ref).sum() / ref.sum()),
                               "mean_ratio": float(img.mean() / ref.mean()),
                               "reference_noise": noise, "frame_ms": [], "volume_ms": []})
            print("%-10s %-34s rel L1 %.3f mean %.3f" % (name, label, scene_rows[-1]["rel_l1"],
                                                         scene_rows[-1]["mean_ratio"]), flush=True)
        big = scene_at(name, args.time_size)
        big["cameras"] = [dict(big["cameras"][0], name="c%d" % i) for i in range(args.copies)]
        for _ in range(args.rounds):
            for row, (label, build, change) in zip(scene_rows, configs(big)):
                _, frames = render(bins[build], apply(big, change, radius),
                                   os.path.join(work, "time"))
                row["frame_ms"].append(statistics.median(f["gpu_ms"] for f in frames))
                row["volume_ms"].append(statistics.median(volume_ms(f) for f in frames))
        for row in scene_rows:
            row["frame_ms"] = statistics.median(row["frame_ms"])
            row["volume_ms"] = statistics.median(row["volume_ms"])
            print("%-10s %-34s frame %.0f ms, volume pass %.0f ms" %
                  (name, row["config"], row["frame_ms"], row["volume_ms"]), flush=True)
        rows += scene_rows
    with open(os.path.join(args.out, "media_grid.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(args.out, "media_grid.md"), "w") as f:
        f.write("| scene | configuration | rel L1 (%d²) | mean / reference | frame ms (%d²) | "
                "volume pass ms |\n|---|---|---|---|---|---|\n" % (args.error_size, args.time_size))
        for r in rows:
            f.write("| %s | %s | %.3f | %.3f | %.0f | %.0f |\n" %
                    (r["scene"], r["config"], r["rel_l1"], r["mean_ratio"], r["frame_ms"],
                     r["volume_ms"]))
        for name in dict.fromkeys(r["scene"] for r in rows):
            noise = next(r["reference_noise"] for r in rows if r["scene"] == name)
            f.write("\nReference noise (%s): %.3f of the rel L1 above.\n" % (name, noise))


if __name__ == "__main__":
    main()
