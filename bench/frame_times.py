#!/usr/bin/env python3
"""Frame time of each effect at several frame sizes, through a beamcast-server.

For each example scene (beams, beams with occluders, the camera inside a
beam, photon-mapped GI, caustics, fog, a layered medium, volumes) and, with
--assets and --slim, each SLIM model beside the mesh it was fitted to, the
scene's first camera is set to SIZE x SIZE and rendered --frames times after
one warm-up request (which traces photons and uploads volumes; later requests
reuse them, as a preview does). Reported per row: the medians of the
server's render_ms (GPU passes, photon upload and read-back; not the PNG
encode), gpu_ms, readback_ms (the read-back call's wall time, which
includes waiting for the GPU to finish the frame) and each pass's GPU ms,
the warm-up request's render_ms, and the passes that ran.

  /usr/bin/python3 bench/frame_times.py --out DIR [--sizes 512 2048]
      [--assets DIR --slim bunny00.bslm:bunny00.off ...]

Writes frame_times.csv and frame_times.md to DIR (and, for each --slim
mesh, MESH.obj beside it in --assets: mesh occluders read OBJ). The CLI's renderer string
(`beamcast info`) names the GPU; pass --info to record it in the table.
"""

import argparse
import csv
import json
import os
import signal
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from beamcast_client import BeamcastClient  # noqa: E402

# (row name, what it exercises, example file)
SCENES = [
    ("beams", "20 beams (the paper's 10 sets)", "paper_10sets.json"),
    ("beams_occluder", "beams, occluders, shadow", "beam_occluder.json"),
    ("camera_inside", "the camera inside a beam", "camera_inside.json"),
    ("gi", "Cornell box: photon-mapped GI, 1e5 photons", "cornell_box.json"),
    ("caustic", "Cornell box with a glass sphere: caustic map", "cornell_caustic.json"),
    ("fog", "fog: in-scattered light, medium photons", "fog_stage.json"),
    ("ground_fog", "a layered medium region", "ground_fog.json"),
    ("beam_fog", "beams seen through a homogeneous medium", "beam_fog.json"),
    ("volume_ml256", "volume ray casting, Marschner-Lobb 256^3", "volume_ml256.json"),
]


def read_off_bounds(path):
    """Axis-aligned bounds of an OFF mesh's vertices."""
    with open(path) as f:
        words = f.read().split()
    i = 1 if words[0] == "OFF" else 0
    nv = int(words[i])
    xyz = [float(w) for w in words[i + 3:i + 3 + 3 * nv]]
    lo = [min(xyz[k::3]) for k in range(3)]
    hi = [max(xyz[k::3]) for k in range(3)]
    return lo, hi


def off_to_obj(assets, mesh):
    """The OFF mesh as OBJ beside it (mesh occluders read OBJ); returns the OBJ's name."""
    obj = mesh + ".obj"
    path = os.path.join(assets, obj)
    if not os.path.exists(path):
        with open(os.path.join(assets, mesh)) as f:
            words = f.read().split()
        i = 1 if words[0] == "OFF" else 0
        nv, nf = int(words[i]), int(words[i + 1])
        i += 3
        with open(path, "w") as out:
            for _ in range(nv):
                out.write("v %s %s %s\n" % tuple(words[i:i + 3]))
                i += 3
            for _ in range(nf):
                n = int(words[i])
                idx = [int(w) + 1 for w in words[i + 1:i + 1 + n]]
                i += 1 + n
                for k in range(1, n - 1):  # a fan of triangles
                    out.write(f"f {idx[0]} {idx[k]} {idx[k + 1]}\n")
    return obj


def slim_scenes(pairs, assets):
    """A SLIM model and the mesh it was fitted to, one scene each, framed alike."""
    out = []
    for pair in pairs:
        model, mesh = pair.split(":")
        lo, hi = read_off_bounds(os.path.join(assets, mesh))
        c = [(a + b) / 2 for a, b in zip(lo, hi)]
        d = max(b - a for a, b in zip(lo, hi))
        cam = {"name": "v", "position": [c[0] + 0.4 * d, c[1] + 0.3 * d, c[2] + 1.8 * d],
               "target": c, "width": 512, "height": 512, "fov_y": 40}
        base = {"background": [0.02, 0.02, 0.03],
                "light": {"direction": [-0.4, -1.0, -0.5], "intensity": 1.0, "ambient": 0.2},
                "cameras": [cam]}
        stem = os.path.splitext(model)[0]
        out.append((f"slim_{stem}", f"SLIM {model} (point sampling)",
                    dict(base, occluders=[{"type": "slim", "file": model}])))
        out.append((f"mesh_{stem}", f"{mesh} rasterized (the SLIM peer)",
                    dict(base, occluders=[{"type": "mesh", "file": off_to_obj(assets, mesh)}])))
    return out


def load_scenes(slim, assets):
    """(name, what, scene) for every example row, then each SLIM pair's two."""
    scenes = []
    for name, what, file in SCENES:
        with open(os.path.join(ROOT, "examples", file)) as f:
            scenes.append((name, what, json.load(f)))
    return scenes + (slim_scenes(slim, assets) if slim else [])


def time_scene(client, name, scene, size, frames, camera=None):
    """Puts `scene` as `name` and renders it `frames` + 1 times, one camera a
    request: the first camera at size x size, or camera(i) for request i
    (a preview's moving camera). Medians over the requests after the first."""
    cam = dict(scene["cameras"][0], width=size, height=size)
    client.scene_put(name, dict(scene, cameras=[cam]))
    rows = []
    for i in range(frames + 1):
        got, result = client.render(scene_id=name, cameras=[camera(i) if camera else cam])
        rows.append((result["timings"]["render_ms"], got[0]))
    first = rows[0][0]
    rows = rows[1:]
    med = statistics.median
    f0 = rows[0][1]
    return {"render_ms": round(med(r for r, _ in rows), 2),
            "gpu_ms": round(med(f["gpu_ms"] for _, f in rows), 2),
            "readback_ms": round(med(f.get("readback_ms", 0.0) for _, f in rows), 2),
            "upload_ms": round(med(f.get("photons", {}).get("upload_ms", 0.0) for _, f in rows), 2),
            "first_render_ms": round(first, 1),
            "passes": {n: round(med(f["pass_ms"][n] for _, f in rows), 2) for n in f0["pass_ms"]},
            "png": rows[-1][1]["png"]}


def write_tables(out, rows, info, frames):
    keys = ["scene", "size", "what", "render_ms", "gpu_ms", "readback_ms", "first_render_ms", "passes", "error"]
    with open(os.path.join(out, "frame_times.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, restval="")
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, "frame_times.md"), "w") as f:
        f.write(f"# Frame time per effect ({info or 'renderer: see beamcast info'})\n\n")
        f.write(f"Medians of {frames} requests after a warm-up request (its render_ms is `first`), "
                "one camera each, through beamcast-server; render = GPU passes + photon upload + read-back "
                "(not the PNG encode); read-back: the read-back call's wall time, waiting for the GPU "
                "included. Per pass: GPU ms.\n\n")
        f.write("| scene | size | render ms | GPU ms | read-back ms | first ms | passes (GPU ms) |\n")
        f.write("|---|---|---|---|---|---|---|\n")
        for r in rows:
            if "error" in r:
                f.write(f"| {r['scene']} | {r['size']} | error: {r['error']} | | | | |\n")
            else:
                f.write(f"| {r['scene']} | {r['size']} | {r['render_ms']} | {r['gpu_ms']} | "
                        f"{r['readback_ms']} | {r['first_render_ms']} | {r['passes']} |\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--server", default=os.path.join(ROOT, "build", "bin", "beamcast-server"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[512, 2048])
    ap.add_argument("--frames", type=int, default=9, help="timed requests per row (median)")
    ap.add_argument("--assets", help="directory of the SLIM models and meshes (--slim)")
    ap.add_argument("--slim", nargs="*", default=[], help="MODEL:MESH pairs in --assets")
    ap.add_argument("--only", nargs="*", help="only these row names")
    ap.add_argument("--info", default="", help="the renderer string, for the table's title")
    ap.add_argument("--images", action="store_true", help="each row's last frame as SCENE_SIZE.png")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)

    scenes = load_scenes(a.slim, a.assets)
    if a.only:
        scenes = [s for s in scenes if s[0] in a.only]

    cmd = [a.server, "--port", "0", "--http-port", "-1", "--max-width", "4096", "--max-height", "4096"]
    if a.assets:
        cmd += ["--assets", a.assets]
    else:
        cmd += ["--assets", os.path.join(ROOT, "examples")]
    # A time limit's SIGTERM ends the run through `finally`, which stops the server.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    rows = []
    try:
        port = int(proc.stdout.readline().rsplit(":", 1)[-1].split()[0])
        with BeamcastClient("127.0.0.1", port, timeout=600) as c:
            for size in a.sizes:
                for name, what, scene in scenes:
                    try:
                        t = time_scene(c, f"{name}_{size}", scene, size, a.frames)
                    except Exception as e:  # one scene's failure is a row, not the end of the run
                        print(f"{name} {size}: {e}", file=sys.stderr, flush=True)
                        rows.append({"scene": name, "size": size, "what": what, "error": str(e)})
                        write_tables(a.out, rows, a.info, a.frames)
                        continue
                    if a.images:
                        with open(os.path.join(a.out, f"{name}_{size}.png"), "wb") as f:
                            f.write(t["png"])
                    row = {"scene": name, "size": size, "what": what,
                           **{k: v for k, v in t.items() if k not in ("passes", "png", "upload_ms")},
                           "passes": " ".join(f"{n} {ms}" for n, ms in t["passes"].items())}
                    rows.append(row)
                    print(json.dumps(row), flush=True)
                    write_tables(a.out, rows, a.info, a.frames)
    finally:
        proc.terminate()
        proc.wait()

    print(f"wrote {a.out}/frame_times.csv and frame_times.md")


if __name__ == "__main__":
    main()
