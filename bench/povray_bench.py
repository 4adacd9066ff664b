#!/usr/bin/python3
"""The Cornell box side by side with POV-Ray 3.7 (issue 14, item 7): time and
error against the same path-traced reference, in one run.
python3 bench/povray_bench.py --out DIR [--size N] [--spp N] [--reuse-references]

The peer is installed here (apt-get install povray, as root) when `povray` is
not on PATH, never by the test command. examples/cornell_box.json is written
as a POV-Ray scene: every quad a two-triangle mesh with pigment = albedo and
finish { diffuse 1, no ambient, no highlights }; the light quad an emitting
surface (pigment = its radiance, emission 1) and no light_source, so light
reaches the room only through POV-Ray's radiosity, which gathers the
cosine-weighted mean of the radiance arriving over the hemisphere (E / pi)
and multiplies it by diffuse x pigment: the Lambertian rho E / pi of the
path tracer, and a Lambertian emitter of the same radiance. The camera is
the scene's (POV-Ray's coordinates are left-handed: `right <-1, 0, 0>`
mirrors them to the scene's right-handed view); output as Radiance HDR,
linear (assumed_gamma 1). POV-Ray's accuracy knobs are its radiosity
settings (count, error_bound, recursion_limit, nearest_count) and
antialiasing; each preset is one row.

Same run, same reference (the mean of two path-traced images of --spp paths a
pixel with different seeds; half their relative L1 difference is its own
noise): Beamcast's default GPU frame (photons traced once; frame time the
median of camera copies, a camera-only change), the path tracer at a few
sample counts, and POV-Ray at each preset (wall time of the whole render,
parsing and radiosity pretrace included, --threads of its render threads).
Per row: relative L1 over the image and per wall (gi_bench's labels), time,
and the time-to-equal-error ratios: POV-Ray's and the path tracer's time to
Beamcast's error (log-log interpolation between their rows; "not reached"
if none of their rows is as accurate) over Beamcast's frame time.
Writes DIR/povray.csv, DIR/povray.md, DIR/povray.png (error against time)
and the images (PNG).
"""
import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gi_bench import CORNELL_LABELS, label_pixels, load_hdr, rel_l1, run_render, write_png  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

# (name, radiosity block, antialiasing options): from POV-Ray's quick look
# to a slow, careful setting. (count 1600, error_bound 0.1 with +A0.05 +R3
# ran over 9 minutes at 512² here and was dropped.)
PRESETS = [
    ("rad-fast", "count 35 error_bound 1.8 recursion_limit 2 nearest_count 5", ["-A"]),
    ("rad-mid", "count 100 error_bound 0.5 recursion_limit 3 nearest_count 10", ["-A"]),
    ("rad-fine", "count 400 error_bound 0.2 recursion_limit 4 nearest_count 10 "
                 "low_error_factor 0.5", ["+A0.1", "+AM2", "+R2"]),
    ("rad-finer", "count 800 error_bound 0.15 recursion_limit 5 nearest_count 15 "
                  "low_error_factor 0.5", ["+A0.1", "+AM2", "+R2"]),
]


def ensure_povray():
    exe = shutil.which("povray")
    if exe:
        return exe
    print("povray not found: installing it (apt-get install povray)", flush=True)
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(["apt-get", "install", "-y", "-q", "povray"], check=True, env=env,
                   stdout=subprocess.DEVNULL)
    exe = shutil.which("povray")
    if not exe:
        sys.exit("povray_bench: povray is still not on PATH after apt-get install povray")
    return exe


def vec(v):
    return "<%r, %r, %r>" % tuple(float(x) for x in v)


def quad_mesh(q, pigment, finish):
    c, u, v = (np.array(q[k], float) for k in ("corner", "edge_u", "edge_v"))
    a, b, d, e = c, c + u, c + u + v, c + v
    return ("mesh { triangle { %s, %s, %s } triangle { %s, %s, %s }\n"
            "  texture { pigment { rgb %s } finish { %s } } }\n" %
            (vec(a), vec(b), vec(d), vec(a), vec(d), vec(e), vec(pigment), finish))


def pov_scene(scene, radiosity):
    cam = scene["cameras"][0]
    assert cam["target"][0] == cam["position"][0] and cam["target"][1] == cam["position"][1], \
        "the exporter handles a camera looking along +z only (the Cornell box's)"
    assert cam["target"][2] > cam["position"][2]
    aspect = cam["width"] / cam["height"]
    # POV-Ray's angle is horizontal; the scene's fov_y is vertical.
    fov_x = math.degrees(2 * math.atan(math.tan(math.radians(cam["fov_y"]) / 2) * aspect))
    out = ["#version 3.7;\n",
           "global_settings { assumed_gamma 1 ambient_light 0 max_trace_level 10\n"
           "  radiosity { %s gray_threshold 0 brightness 1 normal off media off } }\n" % radiosity,
           "background { rgb %s }\n" % vec(scene.get("background", [0, 0, 0])),
           "camera { perspective location %s direction <0, 0, 1> up <0, 1, 0>\n"
           "  right <%r, 0, 0> angle %r }\n" % (vec(cam["position"]), -aspect, fov_x)]
    matte = "ambient 0 emission 0 diffuse 1 brilliance 1 specular 0 phong 0"
    for q in scene["occluders"]:
        assert q["type"] == "quad" and q.get("material", "diffuse") == "diffuse"
        out.append(quad_mesh(q, q.get("albedo", [0.8, 0.8, 0.8]), matte))
    for l in scene["lights"]:
        assert l["type"] == "quad"
        out.append(quad_mesh(l, l["radiance"], "ambient 0 emission 1 diffuse 0"))
    return "".join(out)


def read_rgbe(path):
    """A Radiance HDR file (POV-Ray's +FH): header, resolution, run-length scanlines."""
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    while True:  # header lines up to an empty line
        end = data.index(b"\n", pos)
        line = data[pos:end]
        pos = end + 1
        if line == b"":
            break
    end = data.index(b"\n", pos)
    parts = data[pos:end].split()
    pos = end + 1
    assert parts[0] == b"-Y" and parts[2] == b"+X", parts
    h, w = int(parts[1]), int(parts[3])
    img = np.zeros((h, w, 4), np.uint8)
    for y in range(h):
        if data[pos] == 2 and data[pos + 1] == 2 and (data[pos + 2] << 8 | data[pos + 3]) == w:
            pos += 4
            for c in range(4):
                x = 0
                while x < w:
                    n = data[pos]
                    pos += 1
                    if n > 128:
                        img[y, x:x + n - 128, c] = data[pos]
                        pos += 1
                        x += n - 128
                    else:
                        img[y, x:x + n, c] = np.frombuffer(data, np.uint8, n, pos)
                        pos += n
                        x += n
        else:  # flat scanline
            img[y] = np.frombuffer(data, np.uint8, 4 * w, pos).reshape(w, 4)
            pos += 4 * w
    e = img[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    return img[..., :3].astype(np.float64) * scale[..., None]


def time_to(rows, error):
    """Time at `error` by log-log interpolation over (time, error) rows; None if no row
    reaches it; extrapolation (as 1/sqrt for the path tracer) is the caller's."""
    pts = sorted((r["time_s"], r["rel_l1"]) for r in rows)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if (e0 - error) * (e1 - error) <= 0 and e0 != e1:
            f = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    if pts and pts[0][1] <= error:
        return pts[0][0]
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--spp", type=int, default=1024, help="reference paths per pixel, per seed")
    ap.add_argument("--views", type=int, default=4, help="camera copies for the GPU frame time")
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 2,
                    help="POV-Ray render threads (+WT)")
    ap.add_argument("--presets", default=",".join(p[0] for p in PRESETS))
    ap.add_argument("--reuse-references", action="store_true",
                    help="take the references of an earlier run in DIR (same size and spp)")
    a = ap.parse_args()
    povray = ensure_povray()
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(ROOT, "examples", "cornell_box.json")) as f:
        base = json.load(f)
    cam = dict(base["cameras"][0], width=a.size, height=a.size)
    base["cameras"] = [cam]
    labels = label_pixels(base, cam)
    exposure = base.get("output", {}).get("exposure", 1.0)
    walls = sorted(set(CORNELL_LABELS))

    refs = []
    for seed in (1, 2):
        ref_dir = os.path.join(a.out, f"ref{seed}")
        cached = os.path.join(ref_dir, "view.rgb32f")
        if a.reuse_references and os.path.exists(cached):
            refs.append(np.fromfile(cached, np.float32).reshape(a.size, a.size, 3)
                        .astype(np.float64))
            continue
        summary, _ = run_render(a.binary, base, ref_dir,
                                ["--reference", "--spp", str(a.spp), "--seed", str(seed)])
        refs.append(load_hdr(summary["frames"][0]))
    ref = 0.5 * (refs[0] + refs[1])
    noise = rel_l1(refs[0], refs[1]) / 2
    write_png(os.path.join(a.out, "reference.png"), ref, exposure)
    print("reference: 2 x %d spp, its own noise %.4f" % (a.spp, noise), flush=True)

    rows = []

    def add(tool, setting, img, seconds, note=""):
        row = {"tool": tool, "setting": setting, "time_s": round(seconds, 4),
               "rel_l1": round(rel_l1(img, ref), 4),
               "mean_ratio": round(float(img.mean() / ref.mean()), 4)}
        for w in walls:
            mask = np.isin(labels, [i for i, l in enumerate(CORNELL_LABELS) if l == w])
            row["rel_l1_" + w.replace(" ", "_")] = round(rel_l1(img, ref, mask), 4)
        row["note"] = note
        rows.append(row)
        print(json.dumps(row), flush=True)

    # Beamcast's default frame: photons traced on the first camera, the
    # camera copies (nudged by a hair) time a camera-only change.
    s = dict(base, cameras=[dict(cam, name=f"v{i}", position=[cam["position"][0] + 0.01 * i] +
                                 cam["position"][1:]) for i in range(a.views)])
    summary, _ = run_render(a.binary, s, os.path.join(a.out, "beamcast"), [])
    frames = summary["frames"]
    gpu = load_hdr(frames[0])
    trace_ms = frames[0]["photons"]["trace_ms"]
    frame_ms = statistics.median(f["wall_ms"] for f in frames[1:] or frames)
    add("beamcast", "default (1e5 photons)", gpu, frame_ms / 1000,
        "camera-only change; tracing the photons adds %.0f ms" % trace_ms)
    write_png(os.path.join(a.out, "beamcast.png"), gpu, exposure)

    for spp in (4, 16, 64):
        summary, wall = run_render(a.binary, base, os.path.join(a.out, "pt"),
                                   ["--reference", "--spp", str(spp), "--seed", "7"])
        add("path tracer", f"{spp} spp", load_hdr(summary["frames"][0]),
            summary["frames"][0]["wall_ms"] / 1000)

    wanted = a.presets.split(",")
    for name, radiosity, aa in PRESETS:
        if name not in wanted:
            continue
        pov = os.path.join(a.out, f"{name}.pov")
        with open(pov, "w") as f:
            f.write(pov_scene(base, radiosity))
        hdr = os.path.join(a.out, f"{name}.hdr")
        t0 = time.perf_counter()
        subprocess.run([povray, f"+I{pov}", f"+O{hdr}", "+FH", f"+W{a.size}", f"+H{a.size}",
                        f"+WT{a.threads}", "-D", "-V", "+GA"] + aa,
                       check=True, capture_output=True)
        seconds = time.perf_counter() - t0
        img = read_rgbe(hdr)
        add("POV-Ray 3.7", name, img, seconds, "radiosity { %s }, %s" % (radiosity, " ".join(aa)))
        write_png(os.path.join(a.out, f"{name}.png"), img, exposure)

    ours = rows[0]
    pt = [r for r in rows if r["tool"] == "path tracer"]
    pov = [r for r in rows if r["tool"] == "POV-Ray 3.7"]
    t_pt = time_to(pt, ours["rel_l1"])
    if t_pt is None and pt:  # beyond the rows: the path tracer's error falls as 1/sqrt(time)
        last = max(pt, key=lambda r: r["time_s"])
        t_pt = last["time_s"] * (last["rel_l1"] / ours["rel_l1"]) ** 2
    t_pov = time_to(pov, ours["rel_l1"])

    with open(os.path.join(a.out, "povray.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "povray.md"), "w") as f:
        f.write("Cornell box %dx%d; reference 2 x %d spp (own noise %.4f).\n\n" %
                (a.size, a.size, a.spp, noise))
        cols = [c for c in rows[0].keys() if c != "note"]
        f.write("| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r[c]) for c in cols) + " |\n")
        f.write("\nTime to Beamcast's error (%.4f, %.3f s a frame):\n\n" %
                (ours["rel_l1"], ours["time_s"]))
        f.write("- path tracer: %.1f s, %.0fx Beamcast's frame\n" % (t_pt, t_pt / ours["time_s"]))
        if t_pov is None:
            best = min(pov, key=lambda r: r["rel_l1"]) if pov else None
            f.write("- POV-Ray: not reached (its best row: %s at %.1f s)\n" %
                    ((best["rel_l1"], best["time_s"]) if best else ("none", 0.0)))
        else:
            f.write("- POV-Ray: %.1f s, %.0fx Beamcast's frame\n" %
                    (t_pov, t_pov / ours["time_s"]))
        f.write("\nPOV-Ray settings:\n\n")
        for r in pov:
            f.write("- %s: %s\n" % (r["setting"], r["note"]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for tool, mark in (("path tracer", "s--"), ("POV-Ray 3.7", "^-")):
        sel = sorted((r for r in rows if r["tool"] == tool), key=lambda r: r["time_s"])
        ax.loglog([r["time_s"] for r in sel], [r["rel_l1"] for r in sel], mark, label=tool)
    ax.loglog([ours["time_s"]], [ours["rel_l1"]], "o", ms=9, label="Beamcast (default frame)")
    ax.axhline(noise, color="grey", ls=":", label="reference's own noise")
    ax.set_xlabel("seconds per frame (this machine: llvmpipe and 2 cores)")
    ax.set_ylabel("relative L1 against the path-traced reference")
    ax.set_title("Cornell box %d²: time against error" % a.size, fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "povray.png"), dpi=110)


if __name__ == "__main__":
    main()
