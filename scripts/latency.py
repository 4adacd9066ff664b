#!/usr/bin/env python3
"""End-to-end latency of one frame, split by stage, as the server measures it.

Starts beamcast-server on a free port (or uses --server HOST:PORT), renders the
stored scene N times one request at a time, and prints the median of each
stage: queue, render (GPU work + read-back), read-back, encode, network
(client end-to-end minus server time) and end-to-end.

  scripts/latency.py [--server HOST:PORT] [--count 30] [--scene-id demo]
"""
import argparse
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "client", "python"))
import beamcast_client  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--server")
    ap.add_argument("--binary", default=os.path.join(os.path.dirname(__file__), "..", "build", "bin", "beamcast-server"))
    ap.add_argument("--count", type=int, default=30)
    ap.add_argument("--scene-id", default="demo")
    args = ap.parse_args()
    proc = None
    if args.server:
        host, port = args.server.rsplit(":", 1)
    else:
        proc = subprocess.Popen([args.binary, "--port", "0", "--http-port", "-1"], stdout=subprocess.PIPE,
                                stderr=subprocess.DEVNULL, text=True)
        host, port = proc.stdout.readline().strip().rsplit(" ", 1)[1].rsplit(":", 1)
    client = beamcast_client.BeamcastClient(host, int(port))
    rows = []
    for i in range(args.count + 3):
        frames, result = client.render(scene_id=args.scene_id)
        e2e = result["client_e2e_ms"]
        if i < 3:
            continue  # warm-up: shader JIT, caches
        t = result["timings"]
        rows.append({"queue": t["queue_ms"], "render": t["render_ms"], "readback": t["readback_ms"],
                     "encode": t["encode_ms"], "server": t["server_ms"],
                     "network": e2e - t["server_ms"], "end_to_end": e2e})
    client.close()
    if proc:
        proc.terminate()
        proc.wait()
    f = frames[0]
    print(f"scene '{args.scene_id}', {f['width']}x{f['height']}, median of {len(rows)} requests (ms):")
    for key in ("queue", "render", "readback", "encode", "network", "server", "end_to_end"):
        vals = [r[key] for r in rows]
        print(f"  {key:10s} {statistics.median(vals):8.2f}   (min {min(vals):7.2f}, max {max(vals):7.2f})")


if __name__ == "__main__":
    main()
