#!/usr/bin/env python3
"""SLIM frame time of several `beamcast` binaries, interleaved, as ratios.

Each round runs every binary (the order rotates per round) on the same
model and zoom: `beamcast bench slim --model M --zoom Z --zoom-only
--no-generated --repeats R --evaluation E` (512², the CPU reference
included but not timed), and reads the frame's GPU ms and the slim passes'
ms from slim.csv, and the per-pass medians where the binary prints them.
Reported: per binary the median over rounds, and each binary's median
ratio to the first (--binary order), so machine-wide drift shows in the
spread rather than in the ratio (docs/slim.md)."""
import argparse
import csv
import re
import statistics
import subprocess
import tempfile
from pathlib import Path

PASSES = re.compile(r"passes \(median ms\)(.*)$")


def run(binary: str, model: str, zoom: float, repeats: int, evaluation: str) -> dict:
    with tempfile.TemporaryDirectory() as out:
        done = subprocess.run(
            [binary, "bench", "slim", "--out", out, "--model", model, "--zoom", str(zoom),
             "--zoom-only", "--no-generated", "--repeats", str(repeats), "--evaluation",
             evaluation],
            check=True, capture_output=True, text=True)
        with open(Path(out) / "slim.csv", newline="") as f:
            row = next(csv.DictReader(f))
    got = {"frame": float(row["gpu_ms"]), "slim": float(row["slim_ms"]),
           "normal_p99": float(row["normal_p99_deg"]), "depth_p99": float(row["depth_p99"]),
           "holes": int(row["holes"])}
    for line in done.stderr.splitlines():
        m = PASSES.search(line)
        if m:
            words = m.group(1).split()
            for name, ms in zip(words[::2], words[1::2]):
                got[name] = float(ms)
    return got


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", action="append", required=True,
                    help="NAME=PATH of a beamcast binary (repeatable; the first is the baseline)")
    ap.add_argument("--model", action="append", required=True, help="a SLIM model (repeatable)")
    ap.add_argument("--zoom", type=float, action="append", help="zooms (default 1)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=5, help="frames per run (median)")
    ap.add_argument("--evaluation", default="patch")
    args = ap.parse_args()
    binaries = [b.split("=", 1) for b in args.binary]
    for model in args.model:
        for zoom in args.zoom or [1.0]:
            results = {name: [] for name, _ in binaries}
            for r in range(args.rounds):
                order = binaries[r % len(binaries):] + binaries[:r % len(binaries)]
                for name, path in order:
                    results[name].append(run(path, model, zoom, args.repeats, args.evaluation))
                print(f"{Path(model).stem} zoom {zoom:g} round {r + 1}: " + "  ".join(
                    f"{name} {results[name][-1]['frame']:.1f}" for name, _ in binaries), flush=True)
            base = binaries[0][0]
            print(f"{Path(model).stem} zoom {zoom:g}, {args.rounds} rounds:", flush=True)
            medians = {}
            for name, _ in binaries:
                rows = results[name]
                keys = sorted({k for row in rows for k in row if k.startswith("slim_")} |
                              {"surfaces", "tonemap"} & {k for row in rows for k in row})
                medians[name] = {k: statistics.median(row[k] for row in rows if k in row)
                                 for k in keys}
                passes = "  ".join(f"{k} {medians[name][k]:.1f}" for k in keys)
                ratios = [row["frame"] / b["frame"] for row, b in zip(rows, results[base])]
                print(f"  {name}: frame ms median {statistics.median(r['frame'] for r in rows):.1f} "
                      f"(min {min(r['frame'] for r in rows):.1f}, max {max(r['frame'] for r in rows):.1f}); "
                      f"/{base} median {statistics.median(ratios):.3f} "
                      f"({min(ratios):.3f}-{max(ratios):.3f}); normal p99 {rows[-1]['normal_p99']:.2f}°, "
                      f"depth p99 {rows[-1]['depth_p99']:.4f}, holes {rows[-1]['holes']}; {passes}",
                      flush=True)
            # bench/slim_floor.sh's binaries: each pass's floor from the
            # binary whose fragment work in that pass was taken away.
            if {"floor_depth", "floor_accumulate"} <= medians.keys():
                parts = {"slim_depth": medians["floor_depth"]["slim_depth"],
                         "slim_accumulate": medians["floor_accumulate"]["slim_accumulate"]}
                for k in ("slim_resolve", "surfaces", "tonemap"):
                    parts[k] = medians[base][k]
                print(f"  floor: {sum(parts.values()):.1f} ms = " +
                      " + ".join(f"{k} {v:.1f}" for k, v in parts.items()) +
                      f" (the baseline's frame {statistics.median(r['frame'] for r in results[base]):.1f})",
                      flush=True)


if __name__ == "__main__":
    main()
