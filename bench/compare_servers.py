#!/usr/bin/python3
"""Frame time of two `beamcast-server` binaries on a lit scene, interleaved, as a ratio.

    python3 bench/compare_servers.py --old OLD/beamcast-server --new build/bin/beamcast-server \
        [--scene examples/cornell_box.json] [--size 512] [--rounds 8] [--frames 6]

A camera-only change as the preview makes it (bench/gi_bench.py's
frame_rate): each round starts each server (the order alternates per
round), puts the scene, renders one camera per request (maps traced by the
first, cached after, the camera nudged each time) and takes the medians of
`frames` requests' render_ms (photon upload, GPU, read-back) and passes.
Prints each round, the medians over rounds and new/old per round, so the
machine's drift shows in the spread rather than in the ratio (docs/gi.md,
"Photon clusters and where the frame went")."""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gi_bench import ROOT, frame_rate  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True, help="the reference beamcast-server")
    ap.add_argument("--new", required=True, help="the beamcast-server under test")
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples", "cornell_box.json"))
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--frames", type=int, default=6, help="requests per server and round")
    a = ap.parse_args()
    with open(a.scene) as f:
        scene = json.load(f)
    scene["cameras"] = [dict(scene["cameras"][0], name="v", width=a.size, height=a.size)]
    runs = {"old": [], "new": []}
    for r in range(a.rounds):
        order = [("old", a.old), ("new", a.new)]
        if r % 2:
            order.reverse()
        for name, binary in order:
            runs[name].append(frame_rate(binary, scene, a.frames))
            print(r, name, json.dumps(runs[name][-1]), flush=True)
    for name in ("old", "new"):
        print(f"{name}: render_ms median {statistics.median(x['render_ms'] for x in runs[name]):.1f}")
    ratios = [n["render_ms"] / o["render_ms"] for o, n in zip(runs["old"], runs["new"])]
    print("new/old render_ms per round:", [round(x, 3) for x in ratios],
          f"median {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
