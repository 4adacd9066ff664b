#!/usr/bin/env python3
"""Mixed load against one beamcast-server (issue 13, docs/performance.md "Scheduling").

Starts the given server binary (port 0) with the demo scene, then measures in
one run:
  preview alone   a preview-like loop: one connection, one 512x512 camera on
                  an orbit, "quality": "auto", "motion": "moving", one request
                  at a time (frames/s, latency p50/p99);
  batch alone     a batch loop: one connection keeping 2 renders of 16 cameras
                  (256x256, quality full) in flight (frames/s);
  both            the two loops together;
  fairness        4 connections each keeping 16 single-camera renders in
                  flight (frames/s per connection, min/max);
  cancel          a 64-camera render whose client disconnects after its first
                  streamed part: slices rendered / dropped (stats).
Prints one JSON object. Standard library only (client/python).
"""
import argparse
import json
import math
import os
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "client", "python"))
from beamcast_client import BeamcastClient  # noqa: E402
from local_server import start_server, stop_server  # noqa: E402


def orbit_camera(angle, size, name="cam"):
    r, h = 7.5, 3.5
    return {"name": name, "position": [r * math.sin(angle), h, r * math.cos(angle)],
            "target": [0.0, 0.3, 0.0], "width": size, "height": size, "fov_y": 50}


def pct(values, p):
    if not values:
        return float("nan")
    v = sorted(values)
    return v[min(len(v) - 1, int(math.ceil(p / 100.0 * len(v))) - 1)]


def preview_loop(port, stop, out, fps=0.0):
    """fps > 0: paced like a display (a frame every 1/fps s, or at once when
    late); 0: closed loop, the next request as soon as the last answer came."""
    c = BeamcastClient("127.0.0.1", port)
    lat, frames, k = [], 0, 0
    t0 = time.perf_counter()
    while not stop.is_set():
        if fps > 0:
            due = t0 + k / fps
            if due > time.perf_counter():
                time.sleep(due - time.perf_counter())
        k += 1
        params = {"scene_id": "demo", "cameras": [orbit_camera(0.02 * k, 512)],
                  "quality": "auto", "motion": "moving", "budget_ms": 33}
        t = time.perf_counter()
        c.call("render", params)
        lat.append((time.perf_counter() - t) * 1000.0)
        frames += 1
    out.update(frames=frames, seconds=time.perf_counter() - t0, lat=lat)
    c.close()


def pipelined_loop(port, stop, out, cameras, depth, size):
    c = BeamcastClient("127.0.0.1", port)
    frames, k, pending = 0, 0, 0
    t0 = time.perf_counter()

    def send():
        nonlocal k, pending
        k += 1
        cams = [orbit_camera(2 * math.pi * (i + 0.37 * k) / max(cameras, 1), size, f"c{i}")
                for i in range(cameras)]
        c.send("render", {"scene_id": "demo", "cameras": cams})
        pending += 1

    for _ in range(depth):
        send()
    while pending:
        msg, _ = c.receive()
        pending -= 1
        if not msg.get("ok"):
            raise RuntimeError(msg)
        if not stop.is_set():
            frames += len(msg["result"]["frames"])
            send()
    out.update(frames=frames, seconds=time.perf_counter() - t0)
    c.close()


def run_for(threads, stop, seconds):
    """Starts `threads`, lets them run `seconds`, then sets `stop` and joins them."""
    for t in threads:
        t.start()
    time.sleep(seconds)
    stop.set()
    for t in threads:
        t.join()


def run_phase(port, seconds, preview, batch, fps=0.0):
    stop = threading.Event()
    res_p, res_b, threads = {}, {}, []
    if preview:
        threads.append(threading.Thread(target=preview_loop, args=(port, stop, res_p, fps)))
    if batch:
        threads.append(threading.Thread(target=pipelined_loop,
                                        args=(port, stop, res_b, 16, 2, 256)))
    run_for(threads, stop, seconds)
    out = {}
    if preview:
        out["preview_fps"] = res_p["frames"] / res_p["seconds"]
        out["preview_p50_ms"] = pct(res_p["lat"], 50)
        out["preview_p99_ms"] = pct(res_p["lat"], 99)
    if batch:
        out["batch_fps"] = res_b["frames"] / res_b["seconds"]
    return out


def fairness(port, seconds):
    stop = threading.Event()
    results = [{} for _ in range(4)]
    threads = [threading.Thread(target=pipelined_loop, args=(port, stop, results[i], 1, 16, 128))
               for i in range(4)]
    run_for(threads, stop, seconds)
    fps = [r["frames"] / r["seconds"] for r in results]
    return {"fps": fps, "min_over_max": min(fps) / max(fps)}


def cancel(port):
    c = BeamcastClient("127.0.0.1", port)
    before = c.stats()
    cams = [orbit_camera(2 * math.pi * i / 64, 256, f"x{i}") for i in range(64)]
    c.send("render", {"scene_id": "demo", "cameras": cams, "stream": True})
    c.receive()  # the first part: the render is under way
    c.close()
    s = BeamcastClient("127.0.0.1", port)
    while s.stats()["inflight"] > 0:
        time.sleep(0.05)
    after = s.stats()
    s.close()
    dropped = after.get("slices_dropped", 0) - before.get("slices_dropped", 0)
    return {"slices": 16, "slices_dropped": dropped, "slices_rendered": 16 - dropped,
            "renders_cancelled": after.get("renders_cancelled", 0) -
            before.get("renders_cancelled", 0)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--server-binary", required=True)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--preview-fps", type=float, default=0.0,
                    help="pace the preview loop at this many frames/s (0: closed loop)")
    ap.add_argument("--skip", nargs="*", default=[], help="phases to skip: fairness cancel")
    ap.add_argument("--server-arg", action="append", default=[],
                    help="an extra server option (repeatable), e.g. --server-arg=--no-encode-hold")
    a = ap.parse_args()
    srv, port = start_server([a.server_binary, "--http-port", "0", "--quiet-requests"] + a.server_arg)
    try:
        # Warm-up: tables, programs, the accuracy controller's first levels.
        run_phase(port, 2.0, True, True)
        res = {"load_avg_start": os.getloadavg()[0]}
        res["preview_fps_paced"] = a.preview_fps
        res["preview_alone"] = run_phase(port, a.seconds, True, False, a.preview_fps)
        res["batch_alone"] = run_phase(port, a.seconds, False, True)
        res["both"] = run_phase(port, a.seconds, True, True, a.preview_fps)
        pa, ba, bo = res["preview_alone"], res["batch_alone"], res["both"]
        res["ratios"] = {
            "preview_fps_both_over_alone": bo["preview_fps"] / pa["preview_fps"],
            "preview_p99_both_over_alone": bo["preview_p99_ms"] / pa["preview_p99_ms"],
            "batch_fps_both_over_alone": bo["batch_fps"] / ba["batch_fps"],
        }
        if "fairness" not in a.skip:
            res["fairness"] = fairness(port, a.seconds)
        if "cancel" not in a.skip:
            try:
                time.sleep(1.5)  # past the server's interactive window: full slices
                res["cancel"] = cancel(port)
            except Exception as e:  # an old server has no "stream"
                res["cancel"] = {"error": str(e)}
        res["load_avg_end"] = os.getloadavg()[0]
        print(json.dumps(res, indent=1))
    finally:
        stop_server(srv)


if __name__ == "__main__":
    main()
