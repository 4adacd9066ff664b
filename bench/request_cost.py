#!/usr/bin/env python3
"""The request cost model (protocol/request_cost.hpp) against measured render times.

    python3 bench/request_cost.py build/bin/beamcast-server [--quick]

Starts two servers (--no-demo): one with --max-request-cost 1, whose
limit_exceeded message gives each scene's estimate and its terms, and one
with the limit out of the way, which renders each scene once (a new gi.seed
each run, so no photon map comes from the cache) and reports the client's
round trip. Each calibration scene is made so that one term dominates; the
ratio measured / estimated per scene is what a weight is tuned by
(docs/performance.md, "Request cost"). The examples at their own settings are
listed too.
"""
import json
import os
import re
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "python"))
import test_hostile as th  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def example(name):
    with open(os.path.join(ROOT, "examples", name + ".json")) as f:
        return json.load(f)


def sized(scene, w, h=None):
    for c in scene["cameras"]:
        c["width"], c["height"] = w, h or w
    return scene


def calibration_scenes():
    """(name, scene): one term dominant in each."""
    out = []
    plain = {"occluders": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}],
             "cameras": [{"position": [0, 0, 4], "target": [0, 0, 0], "width": 2048, "height": 2048}]}
    out.append(("pixels: one sphere 2048^2", plain))
    out.append(("beam_pixels: paper_10sets 1024^2", sized(example("paper_10sets"), 1024)))
    box = example("cornell_box")
    box["gi"] = {"photons": 1000000}
    out.append(("photon_bounces: cornell_box 1e6 photons 64^2", sized(box, 64)))
    box = example("cornell_box")
    box["gi"] = {"photons": 10000}
    out.append(("lit_pixels: cornell_box 1e4 photons 1024^2", sized(box, 1024)))
    caus = example("cornell_caustic")
    caus["gi"] = {"photons": 10000, "caustic_photons": 10000}
    out.append(("specular_rays: cornell_caustic 1e4+1e4 1024^2", sized(caus, 1024)))
    caus = example("cornell_caustic")
    caus["gi"] = {"photons": 300000, "caustic_photons": 300000}
    out.append(("photons: cornell_caustic 3e5+3e5 256^2", sized(caus, 256)))
    fog = example("fog_stage")
    fog["gi"] = {"photons": 200000}
    out.append(("volume_photon_views: fog_stage 2e5 256^2", sized(fog, 256)))
    out.append(("medium_pixels: ground_fog 1024^2", sized(example("ground_fog"), 1024)))
    out.append(("volume_samples: volume_ml 512^2", sized(example("volume_ml"), 512)))
    thin = sized(example("volume_ml"), 64)
    thin["volumes"][0]["spacing"] = [0.02, 0.02, 0.0005]
    out.append(("volume_samples: volume_ml thin slab 64^2", thin))
    mesh = example("mesh_occluder")
    mesh["cameras"] = [dict(mesh["cameras"][0], name=f"v{i}") for i in range(16)]
    out.append(("triangle_views: mesh_occluder 16 cameras", mesh))
    return out


def estimate(srv, scene):
    """(total, {term: cost}) from the limit_exceeded message of a server whose limit is 1."""
    c = th.Bcp(srv.port, timeout=60)
    r = c.call({"id": 1, "method": "render", "params": {"scene": scene}})
    c.close()
    msg = r["error"]["message"]
    m = re.search(r"estimated cost is (\S+) \((.*)\), over", msg)
    if not m:
        raise RuntimeError(msg)
    terms = {k: float(v) for k, v in re.findall(r"([a-z_]+) ([0-9.e+-]+)", m.group(2))}
    return float(m.group(1)), terms


def measure(srv, scene, seed):
    scene = json.loads(json.dumps(scene))
    if "lights" in scene:
        scene.setdefault("gi", {})["seed"] = seed
    c = th.Bcp(srv.port, timeout=600)
    t0 = time.monotonic()
    r = c.call({"id": 1, "method": "render", "params": {"scene": scene}})
    ms = (time.monotonic() - t0) * 1000.0
    c.close()
    if not r.get("ok"):
        return None
    return ms


def main():
    th.SERVER = sys.argv[1]
    quick = "--quick" in sys.argv
    cases = calibration_scenes()
    for f in sorted(os.listdir(os.path.join(ROOT, "examples"))):
        if f.endswith(".json"):
            cases.append(("example " + f[:-5], example(f[:-5])))
    if quick:
        cases = cases[:3]
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    with th.Server("--no-demo", "--max-request-cost", "1") as est_srv, \
            th.Server("--no-demo", "--max-request-cost", str(1 << 62)) as run_srv:
        print(f"| scene | estimate | measured ms | measured / estimate | dominant terms |")
        print(f"|---|---|---|---|---|")
        for i, (name, scene) in enumerate(cases):
            total, terms = estimate(est_srv, scene)
            ms = measure(run_srv, scene, 1000 + i)
            top = sorted(terms.items(), key=lambda kv: -kv[1])[:3]
            tops = ", ".join(f"{k} {v:.4g}" for k, v in top)
            shown = f"{ms:.0f}" if ms is not None else "refused"
            ratio = f"{ms / total:.2f}" if ms is not None else "-"
            print(f"| {name} | {total:.0f} | {shown} | {ratio} | {tops} |", flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
