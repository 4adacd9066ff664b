#!/usr/bin/env python3
"""Server RSS after bursts of large legal requests (issue 12, item 9; issue 19;
issue 43, items 6 and 7).

    python3 bench/memory_burst.py build/bin/beamcast-server
                                  [--kinds caustic,fog,volume,slim,mesh,ping]
                                  [--settle 10] [--bound 50]

For each kind, a fresh server (--no-demo, --assets a temporary directory with
the generated files) answers one small request of that kind (so what a first
request allocates for good, the GL context and shader programs included, is in
the baseline), then 4 requests of the kind sent at once on 4 connections, all
within today's limits so that every one is admitted and answered `ok`:

  ping  params of 250 000 small keys (3.0 MB; 4 x 40 x 3.0 MB fits the default
        max_request_memory_bytes, 640 MiB, so none is refused `busy`; under
        max_json_values, 1 000 000)
  mesh  a 64 x 64 render of a scene whose occluder is a 405 000-triangle OBJ
        grid (14 MB; max_mesh_triangles is 1 000 000)
  slim  a 64 x 64 render of a scene whose occluder is a SLIM JSON file of
        100 000 spheres (8 MB; max_slim_spheres is 200 000)
  caustic  examples/cornell_caustic.json at 64 x 64 with 2 M global and 2 M
        caustic photons (max_photons is 4 M)
  fog   issue 43 item 3's point light in a closed sphere of fog, 60 000
        photons of up to 64 events each (see fog_scene)
  volume  a 128 x 128 render of a 256^3 uint8 raw volume file (16 MB;
        max_volume_voxels is 16 Mi)

and prints, per kind, the baseline RSS (lowest sample over 2 s), the RSS
--settle seconds after the last answer (lowest over the last second), the
peak (VmHWM) and the answers. Exits 1 if any kind's RSS after stays more than
--bound MiB (default 50, the issue's bound) above its baseline, or if any
answer is not `ok`. Run it on an old and a new binary back to back to compare
(docs/performance.md, "Memory after large requests").
"""
import argparse
import collections
import json
import os
import shutil
import sys
import tempfile
import threading
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
import test_hostile as th  # noqa: E402

CAMERA = {"name": "c", "position": [0, 2, 6], "target": [0, 0, 0], "width": 64, "height": 64}
BEAM = {"type": "sphere", "center": [0, 0.5, 0], "radius": 1, "density": "linear"}


def write_grid_obj(path, n):
    """An n x n grid of quads in y = -1, as 2 n^2 triangles."""
    with open(path, "w") as f:
        for i in range(n + 1):
            f.write("".join(f"v {-2 + 4 * j / n:.5f} -1 {-2 + 4 * i / n:.5f}\n" for j in range(n + 1)))
        for i in range(n):
            row = []
            for j in range(n):
                a = i * (n + 1) + j + 1
                b, c, d = a + 1, a + n + 2, a + n + 1
                row.append(f"f {a} {b} {c}\nf {a} {c} {d}\n")
            f.write("".join(row))


def write_slim_json(path, count):
    """count flat patches of radius 0.02 on a grid in y = -1."""
    side = int(count ** 0.5) + 1
    spheres = []
    for k in range(count):
        i, j = divmod(k, side)
        spheres.append('{"center":[%.4f,-1,%.4f],"radius":0.02,"coefficients":[0,0,0,0,0,0]}'
                       % (-2 + 4 * j / side, -2 + 4 * i / side))
    with open(path, "w") as f:
        f.write('{"format":"beamcast-slim","version":1,"spheres":[' + ",".join(spheres) + "]}")


def render_text(rid, occluder):
    scene = {"beams": [BEAM], "occluders": [occluder], "cameras": [CAMERA]}
    return json.dumps({"id": rid, "method": "render", "params": {"scene": scene}})


def scene_text(rid, scene):
    return json.dumps({"id": rid, "method": "render", "params": {"scene": scene}})


def write_raw_volume(path, n):
    """An n^3 uint8 field (rows of a ramp, shifted by y + z), headerless."""
    row = bytes((i * 255) // (n - 1) for i in range(n))
    with open(path, "wb") as f:
        for k in range(n):
            f.write(b"".join(row[(j + k) % n:] + row[:(j + k) % n] for j in range(n)))


def volume_scene(n):
    return {"background": [0.02, 0.02, 0.03],
            "volumes": [{"source": {"type": "raw", "file": f"v{n}.raw", "dimensions": [n, n, n],
                                    "format": "uint8"}, "transfer": {"preset": "ml"}}],
            "volume": {"samples_per_voxel": 2, "opacity_correction": True},
            "cameras": [dict(CAMERA, width=128, height=128, position=[2.6, -3.4, 2.0], up=[0, 0, 1])]}


def fog_scene(photons):
    """Issue 43 item 3's scene: a point light in a closed sphere of fog;
    each photon stores up to 64 scattering events (60 000 photons: up to
    3.8 M events, 200 MB of maps, under max_photon_events, max_request_cost
    and the photon cache's 256 MiB, so the maps are kept; 4 of 100 000 at
    once passed max_render_ms waiting on the loaded 2-core machine)."""
    return {"lights": [{"type": "point", "position": [0, 0, 0], "power": 1}],
            "occluders": [{"type": "sphere", "center": [0, 0, 0], "radius": 3}],
            "medium": {"sigma_s": 2},
            "gi": {"photons": photons, "caustic_photons": 0, "max_depth": 64},
            "cameras": [{"width": 64, "height": 64}]}


def caustic_scene(photons):
    """examples/cornell_caustic.json at 64 x 64 with `photons` global and
    caustic photons each."""
    with open(os.path.join(ROOT, "examples", "cornell_caustic.json")) as f:
        scene = json.load(f)
    scene.setdefault("gi", {})
    scene["gi"]["photons"] = photons
    scene["gi"]["caustic_photons"] = photons
    for c in scene["cameras"]:
        c["width"] = c["height"] = 64
    return scene


def ping_text(rid, keys):
    return '{"id":"%s","method":"ping","params":{%s}}' % (
        rid, ",".join(f'"k{i}":{i % 10}' for i in range(keys)))


KINDS = {
    # kind: (file writer or None, request text for an id and "small"/"large")
    "ping": (None, lambda rid, size: ping_text(rid, 10 if size == "small" else 250_000)),
    "mesh": (lambda d: (write_grid_obj(os.path.join(d, "small.obj"), 4),
                        write_grid_obj(os.path.join(d, "large.obj"), 450)),
             lambda rid, size: render_text(rid, {"type": "mesh", "file": size + ".obj"})),
    "slim": (lambda d: (write_slim_json(os.path.join(d, "small.json"), 4),
                        write_slim_json(os.path.join(d, "large.json"), 100_000)),
             lambda rid, size: render_text(rid, {"type": "slim", "file": size + ".json"})),
    "caustic": (None, lambda rid, size: scene_text(rid, caustic_scene(1000 if size == "small" else 2_000_000))),
    "fog": (None, lambda rid, size: scene_text(rid, fog_scene(100 if size == "small" else 60_000))),
    "volume": (lambda d: (write_raw_volume(os.path.join(d, "v8.raw"), 8),
                          write_raw_volume(os.path.join(d, "v256.raw"), 256)),
               lambda rid, size: scene_text(rid, volume_scene(8 if size == "small" else 256))),
}


def answer(port, text, out):
    try:
        c = th.Bcp(port, timeout=300)
        c.send_text(text.encode())
        r = c.recv()[0]
        c.close()
        out.append("ok" if r.get("ok") else r["error"]["code"] + ": " + r["error"]["message"][:120])
    except OSError as e:
        out.append(type(e).__name__)


def run_kind(kind, settle):
    write, request = KINDS[kind]
    assets = tempfile.mkdtemp(prefix="beamcast_burst_")
    try:
        if write:
            write(assets)
        with th.Server("--no-demo", "--assets", assets) as srv:
            warm = []
            answer(srv.port, request("warm", "small"), warm)
            base = th.settle_rss(srv, 2.0)
            burst = []
            threads = [threading.Thread(target=answer, args=(srv.port, request(f"b{i}", "large"), burst))
                       for i in range(4)]
            t0 = time.time()
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            took = time.time() - t0
            time.sleep(max(0.0, settle - 1.0))
            after = th.settle_rss(srv, 1.0)
            peak = srv.status_mib("VmHWM")
            return {"kind": kind, "base": base, "after": after, "peak": peak, "took": took,
                    "answers": dict(collections.Counter(warm + burst))}
    finally:
        shutil.rmtree(assets, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("server")
    ap.add_argument("--kinds", default="caustic,fog,volume,slim,mesh,ping")
    ap.add_argument("--settle", type=float, default=10.0)
    ap.add_argument("--bound", type=float, default=50.0)
    args = ap.parse_args()
    th.SERVER = args.server
    failed = False
    print("| kind | baseline MiB | RSS %.0f s after 4 | growth | peak | burst s | answers |" % args.settle)
    print("|---|---|---|---|---|---|---|")
    for kind in args.kinds.split(","):
        r = run_kind(kind, args.settle)
        grew = r["after"] - r["base"]
        bad = grew > args.bound or set(r["answers"]) != {"ok"}
        failed |= bad
        print(f"| {kind} | {r['base']:.1f} | {r['after']:.1f} | +{grew:.1f} | {r['peak']:.1f} | "
              f"{r['took']:.1f} | {r['answers']} |{' FAIL' if bad else ''}", flush=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
