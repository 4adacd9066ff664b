#!/usr/bin/python3
"""What a frame costs outside GL, per example scene, for two servers interleaved.

    python3 bench/cpu_outside_gl.py --old OLD/beamcast-server --new build/bin/beamcast-server \
        --out DIR [--size 512] [--rounds 2] [--frames 5] [--assets DIR --slim M.bslm:M.off]

Issue 39's per-scene row: each round starts each server in turn (the order
alternates per round), and for every scene of bench/frame_times.py (and
each --slim model beside its mesh) puts the scene, renders one warm-up
request (photon maps traced, volumes uploaded) and `frames` requests of one
camera at SIZE x SIZE, as a client that reuses a stored scene does. Per
request, from the response: server_ms (arrival to the answer queued),
queue_ms, render_ms (passes, upload, read-back), the frame's gpu_ms (timer
queries), readback_ms and encode_ms. "Outside GL" is server_ms - queue_ms -
gpu_ms: everything the server spent on the request but the GPU's work
(scene preparation, read-back wait, encoding, the response). On llvmpipe
the "GPU" is the CPU too; the column is still the part that a GPU does not
take over. Medians over each round's requests, then over rounds; new/old
as the median of the per-round ratios.

Writes cpu_outside_gl.csv and cpu_outside_gl.md to --out.
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from frame_times import ROOT, load_scenes  # noqa: E402
from beamcast_client import BeamcastClient  # noqa: E402

FIELDS = ["server_ms", "render_ms", "gpu_ms", "readback_ms", "encode_ms", "outside_ms"]


def measure(server, scenes, size, frames, assets):
    """One server: {scene: {field: median}} over `frames` requests after a warm-up."""
    cmd = [server, "--port", "0", "--http-port", "-1", "--assets", assets]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    out = {}
    try:
        port = int(proc.stdout.readline().rsplit(":", 1)[-1].split()[0])
        with BeamcastClient("127.0.0.1", port, timeout=600) as c:
            for name, _, scene in scenes:
                cam = dict(scene["cameras"][0], width=size, height=size)
                c.scene_put(name, dict(scene, cameras=[cam]))
                rows = []
                for i in range(frames + 1):
                    got, result = c.render(scene_id=name, cameras=[cam])
                    t = result["timings"]
                    gpu = sum(f["gpu_ms"] for f in got)
                    rows.append({"server_ms": t["server_ms"], "render_ms": t["render_ms"],
                                 "gpu_ms": gpu, "readback_ms": t.get("readback_ms", 0.0),
                                 "encode_ms": t.get("encode_ms", 0.0),
                                 "outside_ms": t["server_ms"] - t.get("queue_ms", 0.0) - gpu})
                rows = rows[1:]
                out[name] = {k: statistics.median(r[k] for r in rows) for k in FIELDS}
                print(f"  {name}: " + " ".join(f"{k} {v:.1f}" for k, v in out[name].items()),
                      flush=True)
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True)
    ap.add_argument("--new", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--assets", default=os.path.join(ROOT, "examples"),
                    help="the servers' --assets: the examples, or a folder with them and --slim's files")
    ap.add_argument("--slim", nargs="*", default=[], help="MODEL:MESH pairs in --assets")
    ap.add_argument("--only", nargs="*", help="only these scene names")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scenes = load_scenes(a.slim, a.assets)
    if a.only:
        scenes = [s for s in scenes if s[0] in a.only]
    runs = {"old": [], "new": []}
    for r in range(a.rounds):
        order = [("old", a.old), ("new", a.new)]
        if r % 2:
            order.reverse()
        for label, server in order:
            print(f"round {r + 1}, {label}", flush=True)
            runs[label].append(measure(server, scenes, a.size, a.frames, a.assets))
    med = statistics.median
    table = []
    for name, what, _ in scenes:
        row = {"scene": name, "what": what}
        for label in ("old", "new"):
            for k in FIELDS:
                row[f"{label}_{k}"] = round(med(run[name][k] for run in runs[label]), 2)
        ratios = [n[name]["outside_ms"] / o[name]["outside_ms"]
                  for o, n in zip(runs["old"], runs["new"]) if o[name]["outside_ms"] > 0]
        row["outside_new_over_old"] = round(med(ratios), 3) if ratios else ""
        table.append(row)
    with open(os.path.join(a.out, "cpu_outside_gl.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(table[0].keys()))
        w.writeheader()
        w.writerows(table)
    with open(os.path.join(a.out, "cpu_outside_gl.md"), "w") as f:
        f.write(f"# Outside GL per frame, {a.size}x{a.size}, old and new servers interleaved\n\n")
        f.write(f"old: `{a.old}`; new: `{a.new}`; {a.rounds} rounds x {a.frames} requests after a "
                "warm-up, one camera a request on a stored scene. Medians in ms. Outside GL = "
                "server_ms - queue_ms - gpu_ms; new/old: median of per-round ratios.\n\n")
        f.write("| scene | outside GL old | outside GL new | new/old | encode old | encode new | "
                "render - GPU old | render - GPU new | read-back old | read-back new | GPU old | GPU new |\n")
        f.write("|---|" + "---|" * 11 + "\n")
        for r in table:
            f.write(f"| {r['scene']} | {r['old_outside_ms']} | {r['new_outside_ms']} | "
                    f"{r['outside_new_over_old']} | {r['old_encode_ms']} | {r['new_encode_ms']} | "
                    f"{round(r['old_render_ms'] - r['old_gpu_ms'], 2)} | "
                    f"{round(r['new_render_ms'] - r['new_gpu_ms'], 2)} | {r['old_readback_ms']} | "
                    f"{r['new_readback_ms']} | {r['old_gpu_ms']} | {r['new_gpu_ms']} |\n")
    print(open(os.path.join(a.out, "cpu_outside_gl.md")).read())


if __name__ == "__main__":
    main()
