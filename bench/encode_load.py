#!/usr/bin/python3
"""End-to-end frames/s of two `beamcast-server` binaries under `beamcast load`,
interleaved, as ratios: the old server (PNG as it encoded it), the new one with
its default PNG encoder and with raw / raw_zstd frames (issue 39, item 1).

    python3 bench/encode_load.py --old OLD/beamcast-server --new build/bin/beamcast-server \
        [--beamcast build/bin/beamcast] [--scene examples/paper_10sets.json] [--rounds 4] \
        [--duration 10] [--connections 4] [--server-args "..."]

Both servers run for the whole measurement (started once, each on its own
port; only one is loaded at a time). Each round runs every configuration once,
in an order rotated per round, as `beamcast load --json` (closed loop, every
frame decoded by the client); it prints each run, the medians, and per round
the ratio of each new configuration's frames/s to the old server's."""
import argparse
import json
import os
import shlex
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from local_server import start_server, stop_server  # noqa: E402


def load(beamcast, port, scene, a, frame_format):
    cmd = [beamcast, "load", "--server", f"127.0.0.1:{port}", "--scene", scene,
           "--connections", str(a.connections), "--duration", str(a.duration), "--json",
           "--quiet"]
    if frame_format != "png":
        cmd += ["--frame-format", frame_format]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=a.duration + 120)
    return json.loads(out.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True)
    ap.add_argument("--new", required=True)
    ap.add_argument("--beamcast", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "paper_10sets.json"))
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=10)
    ap.add_argument("--connections", type=int, default=4)
    ap.add_argument("--server-args", default="--quiet-requests --http-port -1 --no-demo")
    ap.add_argument("--old-args", default="", help="more options for the old server only "
                    "(e.g. --png-encoder libpng, with --old the new binary)")
    a = ap.parse_args()
    extra = shlex.split(a.server_args)
    old, old_port = start_server([a.old] + extra + shlex.split(a.old_args))
    new, new_port = start_server([a.new] + extra)
    configs = [("old png", old_port, "png"), ("new png", new_port, "png"),
               ("new raw", new_port, "raw"), ("new raw_zstd", new_port, "raw_zstd")]
    runs = {name: [] for name, _, _ in configs}
    try:
        for r in range(a.rounds):
            order = configs[r % len(configs):] + configs[:r % len(configs)]
            for name, port, fmt in order:
                res = load(a.beamcast, port, a.scene, a, fmt)
                fps = res["frames_per_s"]
                runs[name].append({"fps": fps, "result": res})
                print(r, name, f"{fps:.2f} frames/s", flush=True)
    finally:
        stop_server(old)
        stop_server(new)
    print("\n| configuration | frames/s per round | median | new/old per round | median ratio |")
    print("|---|---|---|---|---|")
    for name, _, _ in configs:
        f = [x["fps"] for x in runs[name]]
        ratios = [n / o for n, o in zip(f, (x["fps"] for x in runs["old png"]))]
        print(f"| {name} | {', '.join(f'{x:.1f}' for x in f)} | {statistics.median(f):.1f} | "
              f"{', '.join(f'{x:.2f}' for x in ratios)} | {statistics.median(ratios):.2f} |")


if __name__ == "__main__":
    main()
