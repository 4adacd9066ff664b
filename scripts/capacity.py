#!/usr/bin/python3
"""Capacity and overload measurements with `beamcast load` (docs/performance.md,
"Capacity and overload"). Starts beamcast-server on a free port, runs the load
tool at each concurrency and frame size, samples the server's RSS, and writes
the raw JSON results plus a markdown table.

  scripts/capacity.py --build build --out /tmp/capacity [--duration 15]
      [--sizes 256,512] [--connections 1,2,4,8,16,64,256]
      [--overload-factor 10] [--only sweep|overload|soak60]
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import threading
import time


def start_server(binary, extra):
    p = subprocess.Popen([binary, "--port", "0", "--http-port", "-1", "--quiet-requests", *extra],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = p.stdout.readline()
    if "listening on" not in line:
        raise SystemExit("server did not start: " + line)
    return p, line.strip().split()[-1]


def rss_mib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


class RssSampler:
    def __init__(self, pid, period=0.25):
        self.pid, self.period, self.samples, self.stop = pid, period, [], False
        self.t = threading.Thread(target=self.run, daemon=True)
        self.t.start()

    def run(self):
        t0 = time.time()
        while not self.stop:
            self.samples.append((time.time() - t0, rss_mib(self.pid)))
            time.sleep(self.period)

    def finish(self):
        self.stop = True
        self.t.join()
        return self.samples


def load(beamcast, addr, **kw):
    args = [beamcast, "load", "--server", addr, "--json", "--quiet"]
    for k, v in kw.items():
        args += ["--" + k.replace("_", "-"), str(v)]
    out = subprocess.run(args, capture_output=True, text=True)
    if out.returncode not in (0, 3):
        raise SystemExit(f"load failed ({out.returncode}): {out.stderr}")
    return json.loads(out.stdout)


def bottleneck(r):
    """The stage that dominates the mean latency of answered requests."""
    st = r["server_timings_ms"]
    parts = {
        "queue": st["queue"]["mean"],
        "render": st["render"]["mean"],
        "encode": st["encode"]["mean"],
        "network": max(0.0, r["latency_ms"]["mean"] - st["server"]["mean"]),
    }
    return max(parts, key=parts.get), parts


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="/tmp/capacity")
    ap.add_argument("--duration", type=float, default=15)
    ap.add_argument("--sizes", default="256,512")
    ap.add_argument("--connections", default="1,2,4,8,16,64,256")
    ap.add_argument("--overload-factor", type=float, default=10)
    ap.add_argument("--only", default="sweep,overload")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    bindir = pathlib.Path(a.build) / "bin"
    server_bin, beamcast = str(bindir / "beamcast-server"), str(bindir / "beamcast")
    only = a.only.split(",")
    results = {}

    if "soak60" in only:
        srv, addr = start_server(server_bin, [])
        try:
            s = RssSampler(srv.pid)
            r = load(beamcast, addr, connections=16, duration=60, verify_fraction=0.05)
            r["server_rss_mib"] = [round(v, 1) for _, v in s.finish()][::4]
            results["load16x60"] = r
            (out / "load16x60.json").write_text(json.dumps(r, indent=2))
            print(json.dumps({k: r[k] for k in ("requests", "frames_per_s", "mb_per_s", "latency_ms",
                                                "verify", "errors_by_code")}, indent=1))
        finally:
            srv.terminate()
            srv.wait()

    if "sweep" in only:
        rows = []
        for size in [int(x) for x in a.sizes.split(",")]:
            srv, addr = start_server(server_bin, ["--max-connections", "1024"])
            try:
                for n in [int(x) for x in a.connections.split(",")]:
                    s = RssSampler(srv.pid)
                    r = load(beamcast, addr, connections=n, duration=a.duration, size=size,
                             poses="mix", cameras=1, verify_fraction=0.01)
                    rss = s.finish()
                    b, parts = bottleneck(r)
                    row = {"size": size, "connections": n, "fps": r["frames_per_s"],
                           "mbps": r["mb_per_s"], "p50": r["latency_ms"]["p50"],
                           "p99": r["latency_ms"]["p99"], "errors": r["errors_by_code"],
                           "bottleneck": b, "parts_ms": parts,
                           "rss_max_mib": max(v for _, v in rss),
                           "verified": r["verify"]["all_frames_correct"]}
                    rows.append(row)
                    print(json.dumps(row), flush=True)
                    (out / f"sweep_{size}_{n}.json").write_text(json.dumps(r, indent=2))
            finally:
                srv.terminate()
                srv.wait()
        results["sweep"] = rows
        (out / "sweep.json").write_text(json.dumps(rows, indent=2))

    if "overload" in only:
        size = 256
        srv, addr = start_server(server_bin, ["--max-connections", "1024"])
        try:
            base = load(beamcast, addr, connections=4, duration=a.duration, size=size, cameras=1)
            capacity = base["requests_per_s"]
            rate = capacity * a.overload_factor
            s = RssSampler(srv.pid)
            over = load(beamcast, addr, connections=64, duration=30, size=size, cameras=1,
                        rate=f"{rate:.1f}", inflight=16, verify_fraction=0.01)
            rss_over = s.finish()
            s = RssSampler(srv.pid)
            after = load(beamcast, addr, connections=4, duration=a.duration, size=size, cameras=1)
            rss_after = s.finish()
            res = {"capacity_rps": capacity, "offered_rps": rate, "baseline": base, "overload": over,
                   "recovery": after, "rss_overload_mib": [round(v, 1) for _, v in rss_over],
                   "rss_after_mib": [round(v, 1) for _, v in rss_after]}
            (out / "overload.json").write_text(json.dumps(res, indent=2))
            summary = {
                "capacity_rps": round(capacity, 1), "offered_rps": round(rate, 1),
                "overload": {"sent": over["requests"], "errors": over["errors_by_code"],
                             "ok_rps": over["requests_per_s"], "admitted_latency_ms": over["latency_ms"]},
                "rss_mib": {"max_overload": max(rss_over), "end_after": rss_after[-1]},
                "baseline_latency_ms": base["latency_ms"], "recovery_latency_ms": after["latency_ms"],
                "recovery_errors": after["errors_by_code"],
            }
            print(json.dumps(summary, indent=1, default=str))
        finally:
            srv.terminate()
            srv.wait()


if __name__ == "__main__":
    main()
