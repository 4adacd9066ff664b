#!/usr/bin/env python3
"""A small client's render latency alone and beside a connection sending costly
legal renders in a loop, against two servers in one run, interleaved.

    python3 bench/starvation.py NEW_SERVER [OLD_SERVER] [--seconds S] [--rounds R]
        [--abuser caustic|fog|specular]

Issue 43, must-show "Starvation": each round starts each server in turn
(--no-demo) and runs, for S seconds each (default 15):

1. alone: a small client renders a 64 x 64 beam scene in a closed loop;
2. beside: the same, while an abuser on a second connection keeps 4 costly
   renders in flight (the caustic Cornell box at 128 x 128 with 1e6 + 1e6
   photons, a new seed each so nothing comes from the photon cache; admitted
   under the default max_request_cost): photon tracing, the photons'
   clustering and search trees and the specular pass. `--abuser fog`: a point
   light in a closed sphere of fog, 1e5 photons up to 64 scattering events
   each, 64 x 64 (issue 43's item 3 at a legal size): photon tracing is
   nearly all of it. `--abuser specular`: the caustic box at 384 x 384 with
   4 x 4 specular rays a pixel traced on the CPU and few photons: the CPU
   `specular` pass inside the slice is most of it (issue 43: a slice of
   seconds, which a server with turns inside slices cuts into 50 ms turns).

Prints per server the small client's renders, p50 / p99 / max (ms) per phase,
pooled over the rounds, the abuser's answers, its median render_ms per slice
(its GL slice; on a server that traces on the render worker this includes the
trace) and trace_ms, and the target "p99 beside <= 2 x p99 alone + one slice".
Latencies are wall clock at the client (the machine's load shifts them; the
servers alternate so both see it).
"""
import argparse
import json
import os
import statistics
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "python"))
import test_hostile as th  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def pct(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p / 100.0 * (len(xs) - 1))))] if xs else float("nan")


def small_loop(port, seconds, out):
    c = th.Bcp(port, timeout=600)
    scene = dict(th.SMALL_SCENE)
    scene["cameras"] = [dict(scene["cameras"][0], width=64, height=64)]
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end:
        t0 = time.monotonic()
        r = c.call({"id": i, "method": "render", "params": {"scene": scene}})
        if r.get("ok"):
            out.append((time.monotonic() - t0) * 1000.0)
        i += 1
    c.close()


def costly_scene(seed):
    with open(os.path.join(ROOT, "examples", "cornell_caustic.json")) as f:
        scene = json.load(f)
    scene["cameras"][0]["width"] = scene["cameras"][0]["height"] = 128
    scene["gi"] = {"seed": seed, "photons": 1000000, "caustic_photons": 1000000}
    return scene


def specular_scene(seed):
    # The CPU specular pass inside the slice: the caustic box at 384 x 384
    # with 4 x 4 rays a mirror or glass pixel and few photons (the trace is
    # short; the pass is most of the slice). On a hardware GL "auto" traces
    # these rays on the GPU; "cpu" keeps the abuser the same everywhere.
    scene = costly_scene(seed)
    scene["cameras"][0]["width"] = scene["cameras"][0]["height"] = 384
    scene["gi"] = {"seed": seed, "photons": 20000, "caustic_photons": 20000,
                   "specular_samples": 4, "specular_tracer": "cpu"}
    return scene


def fog_scene(seed):
    return {"lights": [{"type": "point", "position": [0, 0, 0], "power": 1}],
            "occluders": [{"type": "sphere", "center": [0, 0, 0], "radius": 3}],
            "medium": {"sigma_s": 2},
            "gi": {"seed": seed, "photons": 100000, "caustic_photons": 0, "max_depth": 64},
            "cameras": [{"position": [0, 0, 2.5], "target": [0, 0, 0], "width": 64, "height": 64}]}


def abuser(port, stop, answers, make_scene):
    c = th.Bcp(port, timeout=900)
    sent = 0
    pending = 0
    try:
        while not stop.is_set():
            while pending < 4:
                req = {"id": sent, "method": "render", "params": {"scene": make_scene(1 + sent)}}
                c.send_text(json.dumps(req).encode())
                sent += 1
                pending += 1
            r, _ = c.recv()
            pending -= 1
            answers.append(r["result"] if r.get("ok") else r["error"]["code"])
    finally:
        c.close()  # what is in flight is dropped (a server that can stops tracing it)


def one_round(server, seconds, res, make_scene):
    th.SERVER = server
    srv = th.Server("--no-demo")
    try:
        warm = []
        small_loop(srv.port, 1.0, warm)  # shaders compiled
        small_loop(srv.port, seconds, res["alone"])
        stop = threading.Event()
        t = threading.Thread(target=abuser, args=(srv.port, stop, res["answers"], make_scene))
        t.start()
        time.sleep(1.0)  # the abuser's first renders are in
        small_loop(srv.port, seconds, res["beside"])
        stop.set()
        t.join()
    finally:
        srv.stop()  # a server that cannot stop its traces is killed after 20 s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("new")
    ap.add_argument("old", nargs="?")
    ap.add_argument("--seconds", type=float, default=15.0)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--abuser", choices=["caustic", "fog", "specular"], default="caustic")
    a = ap.parse_args()
    servers = [("new", a.new)] + ([("old", a.old)] if a.old else [])
    results = {name: {"alone": [], "beside": [], "answers": []} for name, _ in servers}
    print(f"abuser: {a.abuser}; load average at start: {os.getloadavg()[0]:.1f}", flush=True)
    for r in range(a.rounds):
        order = servers if r % 2 == 0 else list(reversed(servers))
        for name, path in order:
            one_round(path, a.seconds, results[name],
                      {"caustic": costly_scene, "fog": fog_scene,
                       "specular": specular_scene}[a.abuser])
            print(f"round {r + 1} {name} done, load {os.getloadavg()[0]:.1f}", flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.1f}")
    print("| server | small client | renders | p50 ms | p99 ms | max ms |")
    print("|---|---|---|---|---|---|")
    for name, _ in servers:
        for phase in ("alone", "beside"):
            xs = results[name][phase]
            print(f"| {name} | {phase} | {len(xs)} | {statistics.median(xs):.1f} | "
                  f"{pct(xs, 99):.1f} | {max(xs):.1f} |" if xs else f"| {name} | {phase} | 0 | - | - | - |")
    print()
    print("| server | abuser answers ok / refused | render ms per slice (median) | trace ms (median) "
          "| target 2 x p99 alone + slice | p99 beside |")
    print("|---|---|---|---|---|---|")
    for name, _ in servers:
        ans = results[name]["answers"]
        ok = [x for x in ans if isinstance(x, dict)]
        per_slice = [x["timings"]["render_ms"] for x in ok]  # one camera: one slice
        trace = [f["photons"]["trace_ms"] for x in ok for f in x.get("frames", []) if "photons" in f]
        slice_ms = statistics.median(per_slice) if per_slice else float("nan")
        target = 2 * pct(results[name]["alone"], 99) + slice_ms
        print(f"| {name} | {len(ok)} / {len(ans) - len(ok)} | {slice_ms:.0f} | "
              f"{statistics.median(trace) if trace else float('nan'):.0f} | {target:.0f} | "
              f"{pct(results[name]['beside'], 99):.0f} |")


if __name__ == "__main__":
    main()
