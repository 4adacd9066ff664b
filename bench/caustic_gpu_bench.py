#!/usr/bin/python3
"""Caustics on the GPU (issue 39, item 4): the `specular` pass traced on the
GPU against the CPU (Embree) tracer and against an older build.
python3 bench/caustic_gpu_bench.py --out DIR --binary NEW [--binary OLD ...]

examples/cornell_caustic.json at its default settings:
  - time: each binary (and, for binaries that know gi.specular_tracer, the
    "cpu" setting too) renders --views copies of the camera at --size
    (512 by default) in one `beamcast render` call, --rounds times,
    interleaved (A B C A B C ...); per frame the wall time, the GPU time
    and the specular pass's time (medians over the frames after each
    call's first, whose maps are traced);
  - error: the path-traced reference at --ref-size (2 seeds x --spp) and
    each configuration's frame at that size: relative L1 over the caustic
    region, the mirror and the glass sphere (bench/caustic_bench.py's
    regions).
Writes DIR/caustic_gpu.md and DIR/caustic_gpu.json.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from caustic_bench import regions  # noqa: E402
from gi_bench import ROOT, load_hdr, rel_l1, run_render  # noqa: E402


def knows_tracer(binary):
    """Whether `binary` accepts gi.specular_tracer (builds after issue 39, item 4)."""
    scene = {"lights": [{"type": "point", "position": [0, 1, 0]}],
             "occluders": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}],
             "gi": {"photons": 10, "caustic_photons": 0, "specular_tracer": "cpu"},
             "cameras": [{"position": [0, 1, 3], "target": [0, 0, 0], "width": 8, "height": 8}]}
    path = "/tmp/caustic_gpu_bench_probe.json"
    with open(path, "w") as f:
        json.dump(scene, f)
    p = subprocess.run([binary, "render", path, "-o", "/tmp/caustic_gpu_bench_probe"],
                       capture_output=True, text=True)
    return p.returncode == 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", action="append", required=True, help="beamcast binaries (first: new)")
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "cornell_caustic.json"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--views", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--ref-size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--direct", default=None,
                    help="gi.direct for every configuration (default: the scene's own; "
                         "cornell_caustic's is \"shadow_maps\")")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(a.scene) as f:
        base = json.load(f)
    if a.direct:
        base.setdefault("gi", {})["direct"] = a.direct
    configs = []
    for i, b in enumerate(a.binary):
        tag = "new" if i == 0 else f"old{i}"
        if knows_tracer(b):
            configs += [(f"{tag} gpu", b, "gpu"), (f"{tag} cpu", b, "cpu")]
        else:
            configs.append((f"{tag}", b, None))

    def scene_for(size, views, tracer):
        s = json.loads(json.dumps(base))
        cam = dict(s["cameras"][0], width=size, height=size)
        s["cameras"] = [dict(cam, name=f"v{i}", position=[cam["position"][0] + 0.01 * i] +
                             cam["position"][1:]) for i in range(views)]
        if tracer:
            s.setdefault("gi", {})["specular_tracer"] = tracer
        return s

    timing = {name: {"wall_ms": [], "gpu_ms": [], "specular_ms": []} for name, _, _ in configs}
    for r in range(a.rounds):
        for name, binary, tracer in configs:
            summary, _ = run_render(binary, scene_for(a.size, a.views, tracer),
                                    os.path.join(a.out, "time"), [])
            for f in summary["frames"][1:]:
                timing[name]["wall_ms"].append(f["wall_ms"])
                timing[name]["gpu_ms"].append(f["gpu_ms"])
                # The pass's GL timer: the compute pass on the GPU path; the
                # CPU path's tracing runs between GL commands and is not in it.
                timing[name]["specular_ms"].append(
                    next(p["gpu_ms"] for p in f["passes"] if p["name"] == "specular"))
            print(name, r, json.dumps({k: v[-1] for k, v in timing[name].items()}), flush=True)

    cam = dict(base["cameras"][0], width=a.ref_size, height=a.ref_size)
    ref_scene = dict(base, cameras=[cam])
    region, _, spheres = regions(ref_scene, cam)
    refs = []
    for seed in (1, 2):
        summary, wall = run_render(a.binary[0], ref_scene, os.path.join(a.out, f"ref{seed}"),
                                   ["--reference", "--spp", str(a.spp), "--seed", str(seed)])
        refs.append(load_hdr(summary["frames"][0]))
        print(f"reference seed {seed}: {wall:.0f} s", flush=True)
    ref = 0.5 * (refs[0] + refs[1])
    noise = {k: rel_l1(refs[0], refs[1], m) / 2
             for k, m in (("caustic", region), ("mirror", spheres["mirror"]), ("glass", spheres["glass"]))}
    rows = []
    for name, binary, tracer in configs:
        summary, _ = run_render(binary, scene_for(a.ref_size, 1, tracer), os.path.join(a.out, "err"), [])
        img = load_hdr(summary["frames"][0])
        t = timing[name]
        rows.append({"config": name,
                     "wall_ms": round(statistics.median(t["wall_ms"]), 1),
                     "gpu_ms": round(statistics.median(t["gpu_ms"]), 1),
                     "specular_gl_ms": round(statistics.median(t["specular_ms"]), 1),
                     "rel_l1_caustic": round(rel_l1(img, ref, region), 4),
                     "rel_l1_mirror": round(rel_l1(img, ref, spheres["mirror"]), 4),
                     "rel_l1_glass": round(rel_l1(img, ref, spheres["glass"]), 4)})
        print(json.dumps(rows[-1]), flush=True)
    with open(os.path.join(a.out, "caustic_gpu.json"), "w") as f:
        json.dump({"rows": rows, "noise": noise, "timing": timing}, f, indent=1)
    with open(os.path.join(a.out, "caustic_gpu.md"), "w") as f:
        f.write(f"Frames of {a.size}x{a.size} ({a.views} camera copies a call, {a.rounds} calls "
                f"each, interleaved; medians of the frames after each call's first). Error at "
                f"{a.ref_size}x{a.ref_size} against the path tracer (2 x {a.spp} spp; its own noise "
                f"over the caustic region {noise['caustic']:.4f}, mirror {noise['mirror']:.4f}, "
                f"glass {noise['glass']:.4f}).\n\n")
        cols = list(rows[0].keys())
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r[c]) for c in cols) + " |\n")
    print(open(os.path.join(a.out, "caustic_gpu.md")).read())


if __name__ == "__main__":
    main()
