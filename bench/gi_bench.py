#!/usr/bin/python3
"""Photon-mapped global illumination: error against the path-traced reference
versus time (issue 14, item 6). python3 bench/gi_bench.py --out DIR [--quick].

Runs `beamcast render` (this build) on the Cornell box (examples/cornell_box.json):
  - the reference: `--reference --spp N` (the double-precision path tracer),
    twice with different seeds, so the reference's own noise is measured
    (the L1 difference of two independent references is sqrt(2) x the noise
    of one);
  - the path tracer alone at a few sample counts (time to equal error);
  - the GPU frame (photon splatting) for each setting: photon counts 1e3 ...
    4e6 (default kernel and radius), each kernel at 1e5, the radius at 0.5x
    and 2x its default at 1e5; at 1e5 also direct light from photons (the
    seed's way) in place of the direct pass, and the direct pass's knobs
    (points per quad light 4 and 64, shadow maps of 128 and 512 texels), the
    splats' edge correction off, splatting at 1/2 and 1/8 of the size (the
    default is 1/4), and photons merged into disks (gi.cluster) 0, 0.25 and
    0.5 (the default is 0.35); and output.supersample 2 (antialiasing) at 1e5, 1e6
    and 4e6.
The reference can instead be given as path-traced renders made before
(`--reference-hdr PATH:SPP`, repeated), so a long one serves several runs.
Then the default frame as the preview gets it: one camera per request to a
beamcast-server (next to the binary) holding the scene, maps cached.
Per photon count also the CPU photon gather on the same photons
(`beamcast render --gather radius`: the splat estimator in double, with the
direct pass's term from the same points with exact visibility; and
`--gather nearest`, k = 50): its error against the reference, and the GPU
frame's difference from it (the splatting's and shadow maps' own error).
Per setting: photon tracing time (CPU, first render), photon upload time and
GPU time per frame with the maps cached (median of the scene's cameras:
copies of the one camera), and the relative L1 error against the reference
(sum |gpu - ref| / sum ref over pixels and channels) over the image and per
wall (pixels labelled by the quad each pixel's centre ray hits first,
computed here from the scene's quads).
Writes DIR/gi.csv, DIR/gi.md, DIR/gi.png (error against photon count with the
log-log slope, error against GPU time), and the images (PNG) of the reference
and the default setting. Standard library and numpy; matplotlib for the plot.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
# The quads of examples/cornell_box.json, in order (scripts/make_examples.py).
CORNELL_LABELS = (["floor", "ceiling", "back wall", "green wall", "red wall"] +
                  ["short block"] * 5 + ["tall block"] * 5)


def run_render(binary, scene, out_dir, extra):
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    t0 = time.perf_counter()
    p = subprocess.run([binary, "render", path, "--json", "--hdr", "-o", out_dir] + extra,
                       capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    return json.loads(p.stdout), wall


def frame_rate(server_binary, scene, frames=12):
    """A camera-only change as the preview makes it: one camera per request
    to a beamcast-server holding the scene (maps traced by the first
    request, cached after), the camera nudged each time. Medians over
    `frames` requests after the first: the server's render_ms (photon
    upload, GPU, readback; not the PNG encoding), gpu_ms and each pass
    (bench/frame_times.py's time_scene)."""
    sys.path.insert(0, os.path.join(ROOT, "client", "python"))
    from beamcast_client import BeamcastClient
    from frame_times import time_scene
    proc = subprocess.Popen([server_binary, "--port", "0", "--http-port", "-1"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        port = int(proc.stdout.readline().rsplit(":", 1)[-1].split()[0])
        cam0 = scene["cameras"][0]
        with BeamcastClient("127.0.0.1", port, timeout=300) as c:
            t = time_scene(c, "gi", scene, cam0["width"], frames, camera=lambda i: dict(
                cam0, position=[cam0["position"][0] + 3.0 * (i % 5)] + cam0["position"][1:]))
    finally:
        proc.terminate()
        proc.wait()
    out = {"render_ms": round(t["render_ms"], 1), "gpu_ms": round(t["gpu_ms"], 1),
           "upload_ms": round(t["upload_ms"], 1),
           "passes": {n: round(ms, 1) for n, ms in t["passes"].items()}}
    out["frames_per_s"] = round(1000.0 / out["render_ms"], 2)
    return out


def load_hdr(frame):
    w, h = frame["width"], frame["height"]
    return np.fromfile(frame["hdr_file"], dtype=np.float32).reshape(h, w, 3).astype(np.float64)


def camera_rays(cam):
    """Unit directions of the pixel-centre rays, rows top-down (protocol/camera.cpp)."""
    w, h = cam["width"], cam["height"]
    pos = np.array(cam["position"], float)
    fwd = np.array(cam["target"], float) - pos
    fwd /= np.linalg.norm(fwd)
    up = np.array(cam.get("up", [0, 1, 0]), float)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    th = math.tan(math.radians(cam.get("fov_y", 45.0)) / 2)
    px = (np.arange(w) + 0.5) / w * 2 - 1
    py = ((h - 1 - np.arange(h)) + 0.5) / h * 2 - 1
    nx, ny = np.meshgrid(px, py)
    d = (fwd[None, None, :] + nx[..., None] * th * (w / h) * right + ny[..., None] * th * up)
    return pos, d / np.linalg.norm(d, axis=-1, keepdims=True)


def label_pixels(scene, cam):
    """Per pixel: the index of the first quad occluder hit (-1: none)."""
    o, d = camera_rays(cam)
    best = np.full(d.shape[:2], np.inf)
    label = np.full(d.shape[:2], -1)
    for i, q in enumerate(scene["occluders"]):
        if q["type"] != "quad":
            continue
        c, u, v = (np.array(q[k], float) for k in ("corner", "edge_u", "edge_v"))
        n = np.cross(u, v)
        denom = d @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.dot(c - o, n) / denom
        p = o + t[..., None] * d - c
        n2 = n @ n
        a = np.cross(p, v) @ n / n2
        b = np.cross(u, p) @ n / n2
        ok = (t > 0) & (a >= 0) & (a <= 1) & (b >= 0) & (b <= 1) & (t < best)
        if q.get("sides", 2) == 1:
            ok &= denom < 0
        best = np.where(ok, t, best)
        label = np.where(ok, i, label)
    return label


def rel_l1(img, ref, mask=None):
    diff = np.abs(img - ref).sum(axis=-1)
    tot = ref.sum(axis=-1)
    if mask is not None:
        diff, tot = diff[mask], tot[mask]
    s = tot.sum()
    return float(diff.sum() / s) if s > 0 else float("nan")


def default_radius(scene, photons):
    """gi/photon_map.cpp default_photon_radius: 50 photons per disk at 1e5 (800 with the
    direct pass carrying direct light), r ~ photons^(-1/6)."""
    pts = []
    for q in scene["occluders"]:
        c, u, v = (np.array(q[k], float) for k in ("corner", "edge_u", "edge_v"))
        pts += [c, c + u, c + v, c + u + v]
    for q in scene.get("lights", []):
        if q["type"] == "quad":
            c, u, v = (np.array(q[k], float) for k in ("corner", "edge_u", "edge_v"))
            pts += [c, c + u, c + v, c + u + v]
    pts = np.array(pts)
    s = pts.max(axis=0) - pts.min(axis=0)
    area = 2 * (s[0] * s[1] + s[1] * s[2] + s[2] * s[0])
    k0 = 50 if scene.get("gi", {}).get("direct") == "photons" else 800
    k = k0 * (photons / 1e5) ** (2 / 3)
    return math.sqrt(k * area / (math.pi * photons))


def given_reference(specs, size):
    """The reference from renders made before (--reference-hdr PATH:SPP):
    their spp-weighted mean, and its noise: the files split into the two
    groups of most nearly equal spp, whose means A and B (weights wA, wB)
    differ by noise of variance s^2 (1/wA + 1/wB) where the whole mean has
    s^2 / (wA + wB): rel_l1(A, B) x sqrt(wA wB) / (wA + wB)."""
    imgs, w = [], []
    for spec in specs:
        path, spp = spec.rsplit(":", 1)
        imgs.append(np.fromfile(path, dtype=np.float32).reshape(size, size, 3).astype(np.float64))
        w.append(float(spp))
    if len(imgs) < 2:
        sys.exit("--reference-hdr: give at least two independent renders")
    total = sum(w)
    best = None
    for mask in range(1, 2 ** len(w) - 1):
        wa = sum(x for i, x in enumerate(w) if mask >> i & 1)
        if best is None or abs(2 * wa - total) < abs(2 * best[1] - total):
            best = (mask, wa)
    mask, wa = best
    wb = total - wa
    mean = lambda sel: sum(x * im for x, im, s in zip(w, imgs, sel) if s) / sum(
        x for x, s in zip(w, sel) if s)
    sel = [bool(mask >> i & 1) for i in range(len(w))]
    a_img, b_img = mean(sel), mean([not x for x in sel])
    noise = rel_l1(a_img, b_img) * math.sqrt(wa * wb) / total
    ref = sum(x * im for x, im in zip(w, imgs)) / total
    desc = (f"{len(imgs)} path-traced renders given, {total:.0f} spp in all "
            f"({', '.join(f'{x:.0f}' for x in w)})")
    return ref, noise, desc


def write_png(path, hdr, exposure):
    """Tone curve 1 - exp(-x), sRGB, 8 bits (render/image.cpp's default), via matplotlib."""
    x = 1 - np.exp(-exposure * np.maximum(hdr, 0))
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        plt.imsave(path, np.clip(srgb, 0, 1))
    except ImportError:
        pass


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "cornell_box.json"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true",
                    help="128x128, reference 64 spp, photons 1e3..1e5 (about a minute)")
    ap.add_argument("--size", type=int, help="frame size (default 512, 128 with --quick)")
    ap.add_argument("--spp", type=int, help="reference samples per pixel (default 1024, 64 quick)")
    ap.add_argument("--views", type=int, default=4,
                    help="camera copies per GPU render (frame time = median over them)")
    ap.add_argument("--reference-hdr", action="append", default=[], metavar="PATH:SPP",
                    help="use these path-traced renders (.rgb32f of this scene at --size, each "
                         "independent, with its spp) as the reference instead of rendering two; "
                         "at least two; repeat the option")
    a = ap.parse_args()
    size = a.size or (128 if a.quick else 512)
    spp = a.spp or (64 if a.quick else 1024)
    os.makedirs(a.out, exist_ok=True)
    with open(a.scene) as f:
        base = json.load(f)
    cam = dict(base["cameras"][0], width=size, height=size)
    base["cameras"] = [cam]
    labels = label_pixels(base, cam)
    exposure = base.get("output", {}).get("exposure", 1.0)

    refs = []
    ref_wall = []
    if a.reference_hdr:
        ref, ref_noise, ref_desc = given_reference(a.reference_hdr, size)
    for seed in ((1, 2) if not a.reference_hdr else ()):
        s = dict(base, gi=dict(base.get("gi", {}), seed=seed))
        # The path tracer's seed is its own option; two renders with
        # different seeds give independent references.
        summary, wall = run_render(a.binary, s, os.path.join(a.out, f"ref{seed}"),
                                   ["--reference", "--spp", str(spp), "--seed", str(seed)])
        refs.append(load_hdr(summary["frames"][0]))
        ref_wall.append(wall)
    if not a.reference_hdr:
        ref = 0.5 * (refs[0] + refs[1])  # the reference: both, 2 x spp
        # Noise of the averaged reference: |ref1 - ref2| / 2 estimates it (each
        # has sqrt(2) x its noise; the mean has 1 / sqrt(2) x).
        ref_noise = rel_l1(refs[0], refs[1]) / 2
        ref_desc = (f"2 x {spp} spp path traced ({ref_wall[0]:.0f} + {ref_wall[1]:.0f} s wall)")
    write_png(os.path.join(a.out, "reference.png"), ref, exposure)

    # Up to 4e6: the server's photon limit (max_photons 4 000 000) is the
    # top a client can ask for.
    counts = [1000, 3000, 10000, 30000, 100000] if a.quick else \
        [1000, 3000, 10000, 30000, 100000, 300000, 1000000, 4000000]
    mid = 10000 if a.quick else 100000
    # (knob, photons, kernel, radius scale, other gi fields, what the row varies)
    settings = [("photons", n, "epanechnikov", 1.0, {}, "") for n in counts]
    settings += [("kernel", mid, k, 1.0, {}, "") for k in ("box", "cone")]
    settings += [("radius", mid, "epanechnikov", s, {}, "") for s in (0.5, 2.0)]
    # Who carries direct light, and the direct pass's own knobs.
    settings += [("direct", mid, "epanechnikov", 1.0, {"direct": "photons"}, "photons")]
    settings += [("direct", mid, "epanechnikov", 1.0, {"direct_samples": k}, f"{k} points")
                 for k in (4, 64)]
    settings += [("direct", mid, "epanechnikov", 1.0, {"shadow_size": k}, f"shadow {k}")
                 for k in (128, 512)]
    # Every point at every pixel (the default shares a quad's points out
    # over a 2 x 2 pattern, gi.direct_interleave 4).
    settings += [("direct", mid, "epanechnikov", 1.0, {"direct_interleave": 1}, "not interleaved")]
    # The splats' edge correction off, and splatting at 1/2, 1/4 and 1/8 size
    # (the default, 0, is 1/8 from 512 pixels a side up, else 1/4).
    settings += [("splat", mid, "epanechnikov", 1.0, {"edge_correction": False}, "no edge corr.")]
    settings += [("splat", mid, "epanechnikov", 1.0, {"splat_scale": k}, f"splat 1/{k}")
                 for k in (2, 4, 8)]
    # The defaults before 2026-11-26 (third session): no interleave, splat 1/4.
    settings += [("direct", mid, "epanechnikov", 1.0, {"direct_interleave": 1, "splat_scale": 4},
                  "earlier default")]
    # Photons merged into disks (gi.cluster; default 0.35): none, finer, coarser.
    settings += [("cluster", mid, "epanechnikov", 1.0, {"cluster": c}, f"cluster {c}")
                 for c in (0.0, 0.25, 0.5)]
    # Antialiasing (output.supersample 2: 4 times the pixels, box-filtered):
    # the reference is a pixel average, so surfaces' outlines differ from a
    # frame sampled at pixel centres; at the default and the top counts.
    settings += [("supersample", n, "epanechnikov", 1.0, {"supersample": 2}, "supersample 2")
                 for n in ([mid] if a.quick else [mid, 1000000, 4000000])]
    regions = sorted(set(CORNELL_LABELS)) if len(base["occluders"]) == len(CORNELL_LABELS) else []

    rows = []
    for knob, n, kernel, rscale, extra, varied in settings:
        extra = dict(extra)
        output = dict(base.get("output", {}))
        if "supersample" in extra:
            output["supersample"] = extra.pop("supersample")
        s = dict(base, gi=dict(base.get("gi", {}), photons=n, kernel=kernel, **extra),
                 output=output)
        r = default_radius(s, n) * rscale
        s["gi"]["radius"] = r
        # Copies of the camera, each nudged by a hair so no two frames are
        # the same work: the maps are traced once, the frames time a
        # camera-only change.
        s["cameras"] = [dict(cam, name=f"v{i}", position=[cam["position"][0] + 0.01 * i] +
                             cam["position"][1:]) for i in range(a.views)]
        summary, wall = run_render(a.binary, s, os.path.join(a.out, "gpu"), [])
        frames = summary["frames"]
        img = load_hdr(frames[0])
        row = {"knob": knob, "photons": n, "kernel": kernel, "radius": round(r, 3),
               "radius_scale": rscale, "direct": varied or "shadow maps",
               "stored": frames[0]["photons"]["count"],
               "disks": frames[0]["photons"]["disks"],
               "trace_ms": round(frames[0]["photons"]["trace_ms"], 1),
               "upload_ms": round(frames[0]["photons"]["upload_ms"], 1),
               "gpu_ms": round(statistics.median(f["gpu_ms"] for f in frames), 1),
               "frame_ms": round(statistics.median(f["wall_ms"] for f in frames), 1),
               "rel_l1": round(rel_l1(img, ref), 4)}
        for reg in regions:
            mask = np.isin(labels, [i for i, l in enumerate(CORNELL_LABELS) if l == reg])
            row["rel_l1_" + reg.replace(" ", "_")] = round(rel_l1(img, ref, mask), 4)
        if knob == "photons":
            # The same photons estimated on the CPU in double: the splat
            # estimator (separates the GPU splatting's own error from the
            # photons' noise and bias) and the textbook k-nearest estimator.
            one = dict(s, cameras=[dict(cam, name="v0")])
            g, _ = run_render(a.binary, one, os.path.join(a.out, "gather"), ["--gather", "radius"])
            gimg = load_hdr(g["frames"][0])
            k, _ = run_render(a.binary, one, os.path.join(a.out, "knn"), ["--gather", "nearest"])
            kimg = load_hdr(k["frames"][0])
            row["gather_ms"] = round(g["frames"][0]["wall_ms"], 1)
            row["gather_rel_l1"] = round(rel_l1(gimg, ref), 4)
            row["splat_vs_gather"] = round(rel_l1(img, gimg), 4)
            row["knn50_rel_l1"] = round(rel_l1(kimg, ref), 4)
        rows.append(row)
        print(json.dumps(row), flush=True)
        if knob == "photons" and n == 100000:
            write_png(os.path.join(a.out, "gpu_1e5.png"), img, exposure)
        if knob == "photons" and n == counts[-1]:
            write_png(os.path.join(a.out, f"gpu_{n}.png"), img, exposure)

    # The default frame as the preview gets it, one camera per request.
    server = os.path.join(os.path.dirname(a.binary), "beamcast-server")
    # And against the defaults before 2026-11-26's third session (every direct
    # point at every pixel, splat 1/4), alternately in 3 rounds: new/old per round.
    rate, old_ratio = None, []
    if os.path.exists(server):
        one = dict(base, cameras=[dict(cam, name="v")])
        old = dict(one, gi=dict(base.get("gi", {}), direct_interleave=1, splat_scale=4))
        for _ in range(3):
            r_new, r_old = frame_rate(server, one), frame_rate(server, old)
            old_ratio.append(round(r_new["render_ms"] / r_old["render_ms"], 3))
            rate = r_new if rate is None or r_new["render_ms"] < rate["render_ms"] else rate
        print("camera-only change, one camera per request: " + json.dumps(rate) +
              f"; new/old per round {old_ratio}", flush=True)

    # The path tracer itself at a few sample counts (another seed than the
    # reference's): its time to reach a given error, against the photons'.
    for spp_pt in ([4, 16] if a.quick else [4, 16, 64]):
        summary, wall = run_render(a.binary, base, os.path.join(a.out, "pt"),
                                   ["--reference", "--spp", str(spp_pt), "--seed", "7"])
        img = load_hdr(summary["frames"][0])
        row = {"knob": "path_tracer", "photons": 0, "kernel": f"{spp_pt} spp", "radius": 0,
               "radius_scale": 0, "direct": "", "stored": 0, "trace_ms": 0, "upload_ms": 0, "gpu_ms": 0,
               "frame_ms": round(summary["frames"][0]["wall_ms"], 1),
               "rel_l1": round(rel_l1(img, ref), 4)}
        for reg in regions:
            mask = np.isin(labels, [i for i, l in enumerate(CORNELL_LABELS) if l == reg])
            row["rel_l1_" + reg.replace(" ", "_")] = round(rel_l1(img, ref, mask), 4)
        rows.append(row)
        print(json.dumps(row), flush=True)

    with open(os.path.join(a.out, "gi.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), restval="")
        w.writeheader()
        w.writerows(rows)
    sweep = [r for r in rows if r["knob"] == "photons"]
    x = np.log10([r["photons"] for r in sweep])
    y = np.log10([r["rel_l1"] for r in sweep])
    slope = float(np.polyfit(x, y, 1)[0]) if len(sweep) > 1 else float("nan")
    with open(os.path.join(a.out, "gi.md"), "w") as f:
        f.write(f"# Photon splatting against the path tracer ({os.path.basename(a.scene)}, "
                f"{size}x{size})\n\n")
        f.write(f"Reference: {ref_desc}; its own noise (rel. L1): {ref_noise:.4f}.\n")
        f.write(f"Log-log slope of error against photon count: {slope:.2f}.\n\n")
        if rate:
            f.write("Camera-only change at the defaults, one camera per request to a "
                    f"beamcast-server (maps cached; median of 12): render {rate['render_ms']} ms "
                    f"(**{rate['frames_per_s']} frames/s**; photon upload {rate['upload_ms']} ms, "
                    f"GPU {rate['gpu_ms']} ms: " +
                    ", ".join(f"{k} {v}" for k, v in rate["passes"].items()) + " ms; the fastest "
                    "of 3 rounds). Its render time over the earlier defaults' (gi.direct_interleave "
                    f"1, splat_scale 4), round by round, alternately: {old_ratio}.\n\n")
        cols = list(rows[0].keys())
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r.get(c, "")) for c in cols) + " |\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
        ax[0].loglog([r["photons"] for r in sweep], [r["rel_l1"] for r in sweep], "o-",
                     label=f"image (slope {slope:.2f})")
        for reg in regions:
            key = "rel_l1_" + reg.replace(" ", "_")
            ax[0].loglog([r["photons"] for r in sweep], [r[key] for r in sweep], ".--", label=reg,
                         alpha=0.6)
        ax[0].axhline(ref_noise, color="grey", lw=0.8, label="reference noise")
        ax[0].set_xlabel("photons emitted")
        ax[0].set_ylabel("relative L1 error")
        ax[0].legend(fontsize=7)
        for knob, mk in (("photons", "o"), ("kernel", "s"), ("radius", "^"), ("direct", "d"),
                         ("splat", "v"), ("cluster", "P"), ("supersample", "*")):
            pts = [r for r in rows if r["knob"] == knob]
            ax[1].loglog([r["frame_ms"] for r in pts], [r["rel_l1"] for r in pts], mk, label=knob)
        pts = [r for r in rows if r["knob"] == "path_tracer"]
        ax[1].loglog([r["frame_ms"] for r in pts], [r["rel_l1"] for r in pts], "kx--",
                     label="CPU path tracer (spp)")
        ax[1].set_xlabel("ms per frame (photons: cached maps; path tracer: whole frame)")
        ax[1].set_ylabel("relative L1 error")
        ax[1].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "gi.png"), dpi=110)
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
    print(f"slope {slope:.3f}, reference noise {ref_noise:.4f}; wrote {a.out}/gi.csv, gi.md")


if __name__ == "__main__":
    main()
