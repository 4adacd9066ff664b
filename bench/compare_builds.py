#!/usr/bin/env python3
"""Frame time of two `beamcast` binaries on one scene, interleaved, as a ratio.

Each round runs both binaries (the order alternates per round) on the same
scene: `beamcast render SCENE --rig orbit:N --batch B --json`, and takes the
median per-frame wall time the tool reports (render + read-back per frame,
the first frames' shader compilation spread over N). The result is the median
over rounds of new/old and each round's ratio, so machine-wide drift shows
in the spread rather than in the ratio. Used to check that a refactor leaves
a scene's frame time where it was (docs/performance.md)."""
import argparse
import json
import statistics
import subprocess
import tempfile


def frame_ms(binary: str, scene: str, views: int, batch: int) -> float:
    with tempfile.TemporaryDirectory() as out:
        run = subprocess.run(
            [binary, "render", scene, "--rig", f"orbit:{views}", "--batch", str(batch),
             "--json", "-o", out],
            check=True, capture_output=True, text=True)
    return json.loads(run.stdout)["frame_ms"]["p50"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True, help="the reference beamcast binary")
    ap.add_argument("--new", required=True, help="the beamcast binary under test")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--views", type=int, default=9, help="orbit cameras per run")
    ap.add_argument("--batch", type=int, default=1, help="views per render call (1: per camera)")
    args = ap.parse_args()
    old, new, ratios = [], [], []
    for r in range(args.rounds):
        order = [("old", args.old), ("new", args.new)]
        if r % 2:
            order.reverse()
        got = {name: frame_ms(b, args.scene, args.views, args.batch) for name, b in order}
        old.append(got["old"])
        new.append(got["new"])
        ratios.append(got["new"] / got["old"])
        print(f"round {r + 1}: old {got['old']:.1f} ms  new {got['new']:.1f} ms  "
              f"new/old {ratios[-1]:.3f}", flush=True)
    print(f"median frame ms: old {statistics.median(old):.1f}  new {statistics.median(new):.1f}; "
          f"new/old median {statistics.median(ratios):.3f} "
          f"(min {min(ratios):.3f}, max {max(ratios):.3f}, {args.rounds} rounds, "
          f"{args.views} views, batch {args.batch})")


if __name__ == "__main__":
    main()
