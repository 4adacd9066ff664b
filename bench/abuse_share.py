#!/usr/bin/env python3
"""A small client's latency alone and beside a connection sending costly legal renders.

    python3 bench/abuse_share.py build/bin/beamcast-server [SECONDS]

Issue 43, item 4 ("fair shares"): one server (--no-demo); a small client
renders a 64 x 64 beam scene in a closed loop for SECONDS (default 20) alone,
then for SECONDS beside an abuser that keeps 4 costly renders in flight (the
caustic example at 1024 x 1024, under max_request_cost: each is admitted),
then for SECONDS after the abuser has gone. Prints the small client's p50 /
p99 / max and count per phase, the abuser's answers, and the slice time (the
abuser's render ms / its slices) to compare with "p99 beside <= 2 x alone +
one slice" (docs/performance.md, "Request cost").
"""
import json
import os
import statistics
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "python"))
import test_hostile as th  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def pct(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(round(p / 100.0 * (len(xs) - 1))))] if xs else float("nan")


def small_loop(port, seconds, out):
    c = th.Bcp(port, timeout=600)
    scene = dict(th.SMALL_SCENE)
    scene["cameras"] = [dict(scene["cameras"][0], width=64, height=64)]
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end:
        t0 = time.monotonic()
        r = c.call({"id": i, "method": "render", "params": {"scene": scene}})
        if r.get("ok"):
            out.append((time.monotonic() - t0) * 1000.0)
        i += 1
    c.close()


def abuser(port, stop, answers):
    with open(os.path.join(ROOT, "examples", "cornell_caustic.json")) as f:
        scene = json.load(f)
    scene["cameras"][0]["width"] = scene["cameras"][0]["height"] = 1024
    c = th.Bcp(port, timeout=900)
    sent = 0
    pending = 0
    while not stop.is_set() or pending:
        while not stop.is_set() and pending < 4:
            s = json.loads(json.dumps(scene))
            s["gi"] = {"seed": 1 + sent}  # no photon map from the cache
            c.send_text(json.dumps({"id": sent, "method": "render", "params": {"scene": s}}).encode())
            sent += 1
            pending += 1
        r, _ = c.recv()
        pending -= 1
        answers.append(r["result"]["timings"] if r.get("ok") else r["error"]["code"])
    c.close()


def report(name, xs):
    if not xs:
        print(f"| {name} | 0 | - | - | - |")
        return
    print(f"| {name} | {len(xs)} | {statistics.median(xs):.1f} | {pct(xs, 99):.1f} | {max(xs):.1f} |",
          flush=True)


def main():
    th.SERVER = sys.argv[1]
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 20.0
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    with th.Server("--no-demo") as srv:
        alone, beside, after, answers = [], [], [], []
        small_loop(srv.port, seconds, alone)
        stop = threading.Event()
        t = threading.Thread(target=abuser, args=(srv.port, stop, answers))
        t.start()
        time.sleep(1.0)  # the abuser's first renders are queued
        small_loop(srv.port, seconds, beside)
        stop.set()
        t.join()
        small_loop(srv.port, seconds, after)
    print("| small client (64², beams) | renders | p50 ms | p99 ms | max ms |")
    print("|---|---|---|---|---|")
    report("alone", alone)
    report("beside the abuser", beside)
    report("after the abuser", after)
    ok = [a for a in answers if isinstance(a, dict)]
    print(f"abuser answers: {len(ok)} ok, {len(answers) - len(ok)} refused; "
          f"server ms each: {[round(a.get('server_ms', 0)) for a in ok]}")


if __name__ == "__main__":
    main()
