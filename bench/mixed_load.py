#!/usr/bin/python3
"""One server under mixed load (issue 13), measured in one run.

    bench/mixed_load.py [--bin-dir build/bin] [--server-binary PATH] [--out DIR]
                        [--duration 10] [--rounds 3] [--quick]

Starts `beamcast-server` (--server-binary, default BIN_DIR/beamcast-server) on
free ports and measures, against that one server process:

1. Views: 16 views of the paper's 10-set scene in one request against the same
   16 cameras as 16 pipelined requests on one connection, at 256x256 and
   512x512, in interleaved rounds (the order of the two variants alternates
   per round). End-to-end time, ratio one/pipelined, and the server's own
   split of each variant (render wall, GPU from timestamps, read-back,
   encode, queue) from the responses. Then `beamcast bench views -k 16` at
   both sizes against the same server (its CSV/Markdown in OUT/views_SIZE/).
2. Preview under batch load (`beamcast load`): the preview-like closed loop
   alone, the batch-like loop alone, and both together; frames/s and p99 of
   the preview, batch frames/s, and the ratios the issue asks for.
3. Fairness: 4 connections each pipelining 16 single-camera renders;
   per-connection frames/s and max/min.

Prints a Markdown summary and writes OUT/mixed_load.json (every raw result)
and OUT/mixed_load.md. Speed targets are the issue's; this script reports,
it does not pass or fail. `--quick` shortens everything (a smoke run).
"""
import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from beamcast_client import BeamcastClient  # noqa: E402
from local_server import start_server, stop_server  # noqa: E402

SCENE_ID = "mixed-load-bench"


def orbit_cameras(cam, count, size):
    """`count` cameras on the orbit of the scene's first camera around its target."""
    target = cam.get("target", [0, 0, 0])
    d = [cam["position"][i] - target[i] for i in range(3)]
    r = math.sqrt(sum(x * x for x in d))
    az0 = math.atan2(d[0], d[2])
    el = math.asin(max(-1.0, min(1.0, d[1] / r)))
    cams = []
    for k in range(count):
        az = az0 + 2 * math.pi * k / count
        cams.append({"name": f"v{k}", "target": target, "fov_y": cam.get("fov_y", 45),
                     "width": size, "height": size,
                     "position": [target[0] + r * math.cos(el) * math.sin(az),
                                  target[1] + r * math.sin(el),
                                  target[2] + r * math.cos(el) * math.cos(az)]})
    return cams


def server_split(results):
    """Sums of the server's timings over the responses of one variant."""
    s = {"render_ms": 0.0, "gpu_ms": 0.0, "readback_ms": 0.0, "encode_ms": 0.0,
         "queue_ms": 0.0, "server_ms": 0.0}
    for r in results:
        t = r["timings"]
        for k in ("render_ms", "readback_ms", "encode_ms", "queue_ms", "server_ms"):
            s[k] += t.get(k, 0.0)
        batches = {}
        for f in r["frames"]:
            b = f.get("gpu_batch", {})
            batches[b.get("index", 0)] = b.get("gpu_ms", f.get("gpu_ms", 0.0))
        s["gpu_ms"] += sum(batches.values())
    return s


def one_request(c, cams):
    t0 = time.perf_counter()
    rid = c.send("render", {"scene_id": SCENE_ID, "cameras": cams})
    msg, _ = c.receive_for(rid)
    e2e = (time.perf_counter() - t0) * 1000
    if not msg.get("ok"):
        raise SystemExit(f"one request failed: {msg.get('error')}")
    return e2e, [msg["result"]]


def pipelined(c, cams):
    t0 = time.perf_counter()
    ids = [c.send("render", {"scene_id": SCENE_ID, "cameras": [cam]}) for cam in cams]
    results = []
    for rid in ids:
        msg, _ = c.receive_for(rid)
        if not msg.get("ok"):
            raise SystemExit(f"pipelined request failed: {msg.get('error')}")
        results.append(msg["result"])
    e2e = (time.perf_counter() - t0) * 1000
    return e2e, results


def measure_views(port, cam, sizes, rounds, views=16):
    """As `beamcast bench views` measures it (docs/performance.md, "One
    measurement of multi-view"): one connection for every request, its
    connect and hello outside the times; both variants warmed up first (the
    multi-view and the single-camera programs and targets); the time from
    the first request sent to the last response read."""
    out = {}
    with BeamcastClient("127.0.0.1", port, timeout=600) as c:
        for size in sizes:
            cams = orbit_cameras(cam, views, size)
            one_request(c, cams[:2])  # warm both paths: tables, programs, targets
            pipelined(c, cams[:2])
            rows = []
            for rnd in range(rounds):
                order = ["one", "pipelined"] if rnd % 2 == 0 else ["pipelined", "one"]
                row = {"round": rnd}
                for variant in order:
                    e2e, results = (one_request if variant == "one" else pipelined)(c, cams)
                    row[variant] = {"e2e_ms": e2e, **server_split(results)}
                row["ratio"] = row["one"]["e2e_ms"] / row["pipelined"]["e2e_ms"]
                rows.append(row)
                print(f"  views {size}px round {rnd}: one {row['one']['e2e_ms']:.0f} ms, "
                      f"pipelined {row['pipelined']['e2e_ms']:.0f} ms, ratio {row['ratio']:.3f}",
                      flush=True)
            out[size] = rows
    return out


def run_load(beamcast, port, args):
    cmd = [beamcast, "load", "--server", f"127.0.0.1:{port}", "--json", "-q",
           "--verify-fraction", "0"] + args
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    try:
        res = json.loads(p.stdout)
    except json.JSONDecodeError:
        raise SystemExit(f"beamcast load failed ({p.returncode}): {p.stderr[-2000:]}")
    return {c["name"]: c for c in res["classes"]}, res


def measure_mix(beamcast, port, duration, preview_size, batch_size, batch_cameras):
    preview = ["--preview-connections", "1", "--preview-size", str(preview_size)]
    # Two closed-loop connections with two requests each in flight: the render
    # worker always has a batch request queued (the server fully busy).
    batch = ["--batch-connections", "2", "--batch-pipeline", "2", "--batch-cameras",
             str(batch_cameras), "--batch-size", str(batch_size)]
    d = ["--duration", str(duration)]
    runs = {}
    for name, args in (("preview_alone", preview), ("batch_alone", batch),
                       ("mix", preview + batch)):
        classes, raw = run_load(beamcast, port, d + args)
        runs[name] = {"classes": classes, "errors_by_code": raw["errors_by_code"]}
        desc = ", ".join(f"{n} {c['frames_per_s']:.1f} frames/s p99 {c['latency_ms']['p99']:.0f} ms"
                         f" errors {c['requests']['errors']}" for n, c in classes.items())
        print(f"  {name}: {desc}", flush=True)
    pa = runs["preview_alone"]["classes"]["preview"]
    ba = runs["batch_alone"]["classes"]["batch"]
    pm = runs["mix"]["classes"]["preview"]
    bm = runs["mix"]["classes"]["batch"]
    runs["ratios"] = {
        "preview_fps_mix_over_alone": pm["frames_per_s"] / pa["frames_per_s"],
        "preview_p99_mix_over_alone": pm["latency_ms"]["p99"] / pa["latency_ms"]["p99"],
        "batch_fps_mix_over_alone": bm["frames_per_s"] / ba["frames_per_s"],
    }
    return runs


def measure_fairness(beamcast, port, duration, size):
    classes, raw = run_load(beamcast, port, ["-c", "4", "--pipeline", "16", "--cameras", "1",
                                             "--size", str(size), "--duration", str(duration)])
    c = classes["load"]
    print(f"  fairness: per connection frames/s "
          f"{[round(x['frames_per_s'], 2) for x in c['per_connection']]}, "
          f"max/min {c['fairness_max_over_min']}, errors {c['errors_by_code']}", flush=True)
    return c


def markdown(res):
    md = [f"Machine: {res['machine']}; server `{res['server_binary']}`; {res['date']}.", ""]
    md += ["| 16 views | round ratios one / pipelined | median ratio | one: e2e / render / GPU / "
           "read-back / encode ms | pipelined: e2e / render / GPU / read-back / encode ms (sums) |",
           "|---|---|---|---|---|"]
    for size, rows in res["views"].items():
        def med(v, k):
            return statistics.median(r[v][k] for r in rows)
        parts = lambda v: " / ".join(f"{med(v, k):.0f}" for k in  # noqa: E731
                                     ("e2e_ms", "render_ms", "gpu_ms", "readback_ms", "encode_ms"))
        ratios = ", ".join(f"{r['ratio']:.3f}" for r in rows)
        md.append(f"| {size}² | {ratios} | "
                  f"**{statistics.median(r['ratio'] for r in rows):.3f}** | {parts('one')} | "
                  f"{parts('pipelined')} |")
    m = res["mix"]
    md += ["", "| run | preview frames/s | preview p50 / p99 ms | batch frames/s | batch p99 ms | errors |",
           "|---|---|---|---|---|---|"]
    for name in ("preview_alone", "batch_alone", "mix"):
        cl = m[name]["classes"]
        p, b = cl.get("preview"), cl.get("batch")
        md.append(f"| {name} | {p['frames_per_s']:.1f} | " if p else f"| {name} | - | ")
        if p:
            md[-1] += f"{p['latency_ms']['p50']:.0f} / {p['latency_ms']['p99']:.0f} | "
        else:
            md[-1] += "- | "
        md[-1] += (f"{b['frames_per_s']:.1f} | {b['latency_ms']['p99']:.0f} | " if b else "- | - | ")
        md[-1] += f"{m[name]['errors_by_code'] or 0} |"
    r = m["ratios"]
    md += ["", f"Preview frames/s with batch load / alone: **{r['preview_fps_mix_over_alone']:.3f}** "
           f"(target ≥ 0.8); preview p99 with / alone: **{r['preview_p99_mix_over_alone']:.2f}** "
           f"(target ≤ 2); batch frames/s with preview / alone: **{r['batch_fps_mix_over_alone']:.2f}** "
           f"(target ≥ 0.7)."]
    f = res["fairness"]
    fps = [x["frames_per_s"] for x in f["per_connection"]]
    ratio = f["fairness_max_over_min"]
    md += ["", f"Fairness, 4 connections × 16 pipelined renders at {res['fairness_size']}²: "
           f"frames/s per connection {', '.join(f'{x:.2f}' for x in fps)}; max/min "
           f"**{ratio:.3f}**" if ratio else "Fairness: a connection got no frame", ""]
    return "\n".join(md)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin-dir", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--server-binary", help="default: BIN_DIR/beamcast-server")
    ap.add_argument("--out", default=None, help="output directory (default: a temporary one)")
    ap.add_argument("--duration", type=float, default=10, help="seconds per load run")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of the views pair")
    ap.add_argument("--no-bench-views", action="store_true", help="skip `beamcast bench views`")
    ap.add_argument("--quick", action="store_true", help="a short smoke run")
    a = ap.parse_args()
    beamcast = os.path.join(a.bin_dir, "beamcast")
    server = a.server_binary or os.path.join(a.bin_dir, "beamcast-server")
    out = a.out or tempfile.mkdtemp(prefix="mixed_load_")
    os.makedirs(out, exist_ok=True)
    sizes = [64, 128] if a.quick else [256, 512]
    duration = 2 if a.quick else a.duration
    rounds = 1 if a.quick else a.rounds
    with open(os.path.join(ROOT, "examples", "paper_10sets.json")) as f:
        scene = json.load(f)

    proc, port = start_server([server, "--http-port", "0"])
    try:
        with BeamcastClient("127.0.0.1", port, timeout=120) as c:
            c.call("scene.put", {"scene_id": SCENE_ID, "scene": scene})
        try:
            cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                       if l.startswith("model name"))
        except (OSError, StopIteration):
            cpu = platform.processor()
        res = {"machine": f"{os.cpu_count()} cores ({cpu}), load average "
                          f"{os.getloadavg()[0]:.1f} at start, {platform.platform()}",
               "server_binary": server, "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
               "fairness_size": 64 if a.quick else 128}
        print("1. 16 views: one request vs 16 pipelined requests", flush=True)
        res["views"] = measure_views(port, scene["cameras"][0], sizes, rounds)
        if not a.no_bench_views:
            res["bench_views"] = {}
            for size in sizes:
                d = os.path.join(out, f"views_{size}")
                p = subprocess.run([beamcast, "bench", "views", "--server", f"127.0.0.1:{port}",
                                    "-k", "16", "--size", str(size), "--rounds", str(rounds),
                                    "--no-plots", "--no-renderer", "--out", d],
                                   capture_output=True, text=True, timeout=3600)
                md = os.path.join(d, "views.md")
                res["bench_views"][size] = open(md).read() if os.path.exists(md) else p.stderr
                print(f"  bench views {size}px: {d}/views.md (exit {p.returncode})", flush=True)
        print("2. preview under batch load", flush=True)
        res["mix"] = measure_mix(beamcast, port, duration, sizes[0], sizes[0], 16)
        print("3. fairness: 4 connections x 16 pipelined renders", flush=True)
        res["fairness"] = measure_fairness(beamcast, port, duration, res["fairness_size"])
    finally:
        stop_server(proc)
    with open(os.path.join(out, "mixed_load.json"), "w") as f:
        json.dump(res, f, indent=1)
    md = markdown(res)
    with open(os.path.join(out, "mixed_load.md"), "w") as f:
        f.write(md)
    print()
    print(md)
    print(f"raw results: {out}/mixed_load.json")


if __name__ == "__main__":
    main()
