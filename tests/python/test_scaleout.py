#!/usr/bin/env python3
"""Three beamcast-servers behind HAProxy on loopback (issue 18, ctest -L scaleout).

    python3 tests/python/test_scaleout.py build/bin/beamcast-server build/bin/beamcast

The deployment of deploy/haproxy.cfg.in, end to end: three servers on free
loopback ports, HAProxy in front (its BCP1 port in TCP mode, health from each
server's HTTP /health). Checks, each printed with its numbers:
  1. all three servers come up in HAProxy and renders through it (a new
     connection each, frames verified) reach every one of them;
  2. four clients (client/python's ResilientClient: retries on a new
     connection with backoff and a shared retry budget, the scene put again
     where a server lacks it) render by scene_id for 2 s; then `kill -9` of
     one server under that load: HAProxy marks it down within 1 s (the
     issue's bound; inter 250 ms, fall 3, fastinter 100 ms), no request is
     lost or fails (each frame byte-equal to the first), retries stay within
     the budget (<= 10% of requests + its burst of 10), and the p99 latency
     of the 2 s after the kill is printed beside the steady p99; every
     render on a new connection after detection is answered by the others;
  3. the server restarted on its ports: back up within 2 s (rise 2) and
     given renders again;
  4. `beamcast load` (4 connections, closed loop, frames decoded and 5%
     compared with a local render) through HAProxy for 6 s, another server
     killed with SIGKILL 2.5 s in and restarted 2 s later: every request
     answered correctly, the connections cut reconnected and their requests
     sent again within the budget (amplification <= 1.1, the issue's
     bound), the kill detected within 2 s (the machine saturated: see
     load_failover), and the p99 of the timeline's 250 ms buckets around the kill
     printed beside the steady ones (measured, not asserted: a timing bound
     on a shared 2-core machine belongs to docs/deploy.md's record);
  5. `beamcast render --rig orbit:36` split over the three servers
     (--server A,B,C), with one of them killed mid-job, and through HAProxy
     (--connections 3): each of the 36 frames byte-identical to the same
     job on one server, every server given a share, the killed server's
     unfinished batches rendered by the others.
Plain python3; exits 0 only if every check passed.
"""
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from beamcast_client import BeamcastClient, ResilientClient, RetryBudget  # noqa: E402
from cluster import Cluster  # noqa: E402

SCENE = {
    "beams": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "density": "linear"}],
    "cameras": [{"name": "c", "position": [0, 0, 4], "target": [0, 0, 0],
                 "width": 48, "height": 40}],
}


def render_through(port):
    with BeamcastClient("127.0.0.1", port, timeout=30) as c:
        frames, result = c.render(scene=SCENE)
    png = frames[0]["png"]
    assert png[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    assert png[16:24] == (48).to_bytes(4, "big") + (40).to_bytes(4, "big"), "wrong size"
    return result


def percentile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))] if v else float("nan")


class Load:
    """`threads` closed-loop clients (ResilientClient, one shared RetryBudget)
    rendering SCENE by scene_id through the balancer; each frame is compared
    byte for byte with the first (the same pose renders the same PNG on any
    server of one build). Latencies are kept with their end time."""

    def __init__(self, port, threads):
        self.port, self.budget = port, RetryBudget()
        self.stop = threading.Event()
        self.lock = threading.Lock()
        self.samples = []  # (end time, ms)
        self.failures, self.mismatches = [], 0
        self.reference = None
        self.clients = [ResilientClient("127.0.0.1", port, timeout=30, budget=self.budget,
                                        rng=__import__("random").Random(i))
                        for i in range(threads)]
        self.threads = [threading.Thread(target=self.run, args=(c, f"scaleout-{i}"), daemon=True)
                        for i, c in enumerate(self.clients)]

    def run(self, client, scene_id):
        # Each client its own scene id: one that reconnects to another server
        # finds no scene there (unknown_scene) and puts it again.
        try:
            client.scene_put(scene_id, SCENE)
        except Exception as e:  # noqa: BLE001 - counted and reported
            with self.lock:
                self.failures.append(repr(e))
            return
        while not self.stop.is_set():
            t0 = time.monotonic()
            try:
                frames, _ = client.render(scene_id=scene_id)
            except Exception as e:  # noqa: BLE001 - counted and reported
                with self.lock:
                    self.failures.append(repr(e))
                continue
            t1 = time.monotonic()
            with self.lock:
                if self.reference is None:
                    self.reference = frames[0]["png"]
                elif frames[0]["png"] != self.reference:
                    self.mismatches += 1
                self.samples.append((t1, (t1 - t0) * 1000.0))

    def start(self):
        for t in self.threads:
            t.start()

    def finish(self):
        self.stop.set()
        for t in self.threads:
            t.join(60)
        for c in self.clients:
            c.close()

    def between(self, t0, t1):
        with self.lock:
            return [ms for t, ms in self.samples if t0 <= t < t1]

    def totals(self):
        return (sum(c.requests for c in self.clients), sum(c.retries for c in self.clients),
                sum(c.reputs for c in self.clients))


def load_failover(cluster, cli_bin, run_dir, check):
    """Check 4: `beamcast load` through the balancer while server 3 is killed
    and restarted."""
    scene_file = os.path.join(run_dir, "scene.json")
    with open(scene_file, "w") as f:
        json.dump(SCENE, f)
    t0 = time.monotonic()
    proc = subprocess.Popen(
        [cli_bin, "load", "--server", f"127.0.0.1:{cluster.bcp_port}", "-c", "4",
         "--duration", "6", "--size", "48", "--poses", "orbit", "--cameras", "1",
         "--verify-fraction", "0.05", "--timeline-ms", "250", "--scene", scene_file,
         "--json", "-q"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.5)
    kill_at = time.monotonic() - t0
    cluster.procs[2].kill()
    detect = cluster.wait_status("s3", "DOWN", 5)
    time.sleep(max(0.0, t0 + 4.5 - time.monotonic()))
    cluster.start_server(2)
    out, err = proc.communicate(timeout=120)
    if proc.returncode != 0 and not out.strip():
        check("beamcast load through a failover", False, f"exit {proc.returncode}: {err[-2000:]}")
        return
    r = json.loads(out)
    req, retries, verify = r["requests"], r["retries"], r["verify"]
    # The 1 s bound is asserted in check 2. Here the machine is
    # saturated (beamcast load's four closed-loop connections, and under
    # ASan servers 2-3x slower), and what is timed includes the scheduler's
    # delays to HAProxy's check timer and to this poller: CI once read
    # 1.07 s here while check 2 read 0.16 s in the same run. 2 s still
    # tells the configured schedule (inter 250 ms, fastinter 100 ms, fall 3:
    # ~0.45 s) from HAProxy's defaults (inter 2 s, fall 3: ~6 s).
    check("beamcast load: the kill detected within 2 s (1 s asserted in check 2)",
          detect is not None and detect <= 2.0, f"{detect} s")
    check("beamcast load: no request lost or failed, frames verified",
          proc.returncode == 0 and req["errors"] == 0 and req["ok"] == req["sent"] and
          verify["all_frames_correct"] and verify["reference_checked"] > 0,
          f"{req['ok']} / {req['sent']} answered, errors {r['errors_by_code']}; "
          f"{verify['decoded']} frames decoded, {verify['reference_checked']} compared with "
          f"a local render (max diff {verify['reference_max_diff']})")
    check("beamcast load: cut connections reconnected, retries within 1.1x",
          retries["reconnects"] > 0 and retries["amplification"] <= 1.1 and
          retries["refused_by_budget"] == 0,
          f"{retries['reconnects']} reconnects, {retries['requests_sent_again']} requests "
          f"sent again, {retries['scene_reputs']} scene re-puts; amplification "
          f"{retries['amplification']:.4f}")
    # Buckets (250 ms) by the time answers arrived; the load started ~t0.
    steady = [b["p99_ms"] for b in r["timeline"] if 0.5 <= b["t_s"] < kill_at - 0.25 and b["ok"]]
    around = [b for b in r["timeline"] if kill_at - 0.25 <= b["t_s"] < kill_at + 2.0]
    steady_p99 = sorted(steady)[len(steady) // 2] if steady else float("nan")
    worst = max((b["p99_ms"] for b in around), default=float("nan"))
    print(f"  load latency: steady p99 (median of {len(steady)} buckets) {steady_p99:.1f} ms; "
          f"worst bucket p99 in the 2 s after the kill {worst:.1f} ms "
          f"(ratio {worst / steady_p99:.2f}); {r['frames_per_s']:.0f} frames/s overall",
          flush=True)
    print("  timeline (t_s ok errors retries p99_ms): " + ", ".join(
        f"{b['t_s']:.2f} {b['ok']} {b['errors']} {b['retries']} {b['p99_ms']:.1f}"
        for b in r["timeline"]), flush=True)


def batch_render(cluster, cli_bin, run_dir, check):
    """Check 5: one orbit job on one server, on three (one killed mid-job)
    and through the balancer; the frames compared byte for byte."""
    scene = os.path.join(ROOT, "examples", "paper_10sets.json")

    def render(name, servers, extra=(), kill=None):
        out = os.path.join(run_dir, name)
        proc = subprocess.Popen([cli_bin, "render", scene, "--rig", "orbit:36", "--batch", "2",
                                 "--server", servers, "--out", out, "--json", *extra],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if kill is not None:
            time.sleep(0.5)  # every worker holds a batch by then (the job takes ~2 s)
            cluster.procs[kill].kill()
        stdout, stderr = proc.communicate(timeout=120)
        if proc.returncode != 0:
            return None, f"exit {proc.returncode}: {stderr[-1500:]}", out
        return json.loads(stdout), None, out

    def frames(out):
        result = []
        for i in range(36):
            with open(os.path.join(out, f"frame_{i:04d}.png"), "rb") as f:
                result.append(f.read())
        return result

    one, err, out_one = render("one", f"127.0.0.1:{cluster.ports[0][0]}")
    if err:
        check("batch render on one server", False, err)
        return
    want = frames(out_one)
    direct = ",".join(f"127.0.0.1:{p}" for p, _ in cluster.ports)
    for name, servers, extra, kill in (("three", direct, (), 1),
                                       ("balancer", f"127.0.0.1:{cluster.bcp_port}",
                                        ("--connections", "3"), None)):
        before = {k: v[1] for k, v in cluster.stat().items()}
        res, err, out = render(name, servers, extra, kill)
        spread = {k: v[1] - before.get(k, 0) for k, v in cluster.stat().items()}
        if err:
            check(f"batch render ({name})", False, err)
            continue
        got = frames(out)
        same = sum(a == b for a, b in zip(want, got))
        shares = [(w["server"], w["frames"], w["error"] is not None) for w in res["servers"]]
        by_server = {}
        for srv, n, _ in shares:
            by_server[srv] = by_server.get(srv, 0) + n
        detail = (f"{same}/36 frames byte-identical to one server's; frames per worker "
                  f"(server, frames, failed) {shares}")
        if kill is None:
            # The server killed just before is down: the other two share it.
            check("batch render through HAProxy equals one server's",
                  same == 36 and sum(n > 0 for n in spread.values()) >= 2,
                  detail + f"; HAProxy sessions per server {spread}")
        else:
            killed = f"127.0.0.1:{cluster.ports[kill][0]}"
            others = [n for srv, n in by_server.items() if srv != killed]
            failed = [f for srv, _, f in shares if srv == killed]
            check("batch render over three servers, one killed mid-job, equals one server's",
                  same == 36 and all(failed) and all(n > 0 for n in others), detail)


def main():
    server_bin = sys.argv[1]
    cli_bin = sys.argv[2]
    failed = []

    def check(name, ok, detail):
        print(("PASS " if ok else "FAIL ") + name + ": " + detail, flush=True)
        if not ok:
            failed.append(name)

    with tempfile.TemporaryDirectory() as run_dir:
        cluster = Cluster(server_bin, 3, run_dir)
        try:
            cluster.start()
            up = [cluster.wait_status(f"s{i}", "UP", 10) for i in (1, 2, 3)]
            check("all servers up", all(t is not None for t in up), f"after {up} s")
            for _ in range(30):
                render_through(cluster.bcp_port)
            sessions = {k: v[1] for k, v in cluster.stat().items()}
            check("renders reach every server", all(v > 0 for v in sessions.values()),
                  f"sessions per server {sessions} for 30 renders")

            # Steady load for 2 s, then server 2 killed under it for 2 s more.
            load = Load(cluster.bcp_port, 4)
            load.start()
            time.sleep(2.0)
            t_kill = time.monotonic()
            cluster.procs[1].kill()  # kill -9
            detect = cluster.wait_status("s2", "DOWN", 5)
            time.sleep(max(0.0, t_kill + 2.0 - time.monotonic()))
            load.finish()
            steady = load.between(t_kill - 1.5, t_kill)
            failover = load.between(t_kill, t_kill + 2.0)
            requests, retries, reputs = load.totals()
            check("a killed server is marked down within 1 s",
                  detect is not None and detect <= 1.0, f"{detect} s")
            check("no request lost or failed under failover",
                  not load.failures and load.mismatches == 0 and retries > 0 and reputs > 0,
                  f"{len(load.samples)} renders answered, {len(load.failures)} failed "
                  f"{load.failures[:3]}, {load.mismatches} frames not the reference's; "
                  f"{retries} retries and {reputs} scene re-puts for {requests} requests")
            check("retries within the budget", retries <= 0.1 * requests + 10,
                  f"{retries} retries / {requests} requests "
                  f"(amplification {(requests + retries) / max(1, requests):.3f})")
            p99s, p99f = percentile(steady, 0.99), percentile(failover, 0.99)
            print(f"  latency: steady p50 {percentile(steady, 0.5):.1f} ms p99 {p99s:.1f} ms "
                  f"({len(steady)} renders); failover p50 {percentile(failover, 0.5):.1f} ms "
                  f"p99 {p99f:.1f} ms ({len(failover)} renders): ratio {p99f / p99s:.2f}",
                  flush=True)
            before = cluster.stat()["s2"][1]
            errors = 0
            for _ in range(30):
                try:
                    render_through(cluster.bcp_port)
                except Exception as e:  # noqa: BLE001 - counted and reported
                    errors += 1
                    print("  render failed:", e)
            check("renders after detection all answered", errors == 0,
                  f"{30 - errors} / 30 correct frames, none sent to the dead server "
                  f"({cluster.stat()['s2'][1] - before} sessions to it)")

            t0 = time.monotonic()
            cluster.start_server(1)
            back = cluster.wait_status("s2", "UP", 5)
            check("the restarted server is back up within 2 s",
                  back is not None and time.monotonic() - t0 <= 2.5 and back <= 2.0,
                  f"{back} s after its restart")
            before = cluster.stat()["s2"][1]
            for _ in range(30):
                render_through(cluster.bcp_port)
            after = cluster.stat()["s2"][1]
            check("the restarted server gets renders again", after > before,
                  f"{after - before} of 30 sessions")

            load_failover(cluster, cli_bin, run_dir, check)
            batch_render(cluster, cli_bin, run_dir, check)
        finally:
            cluster.stop()
    print(f"{'FAILED: ' + ', '.join(failed) if failed else 'all checks passed'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
