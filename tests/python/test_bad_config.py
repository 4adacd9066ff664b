#!/usr/bin/env python3
"""Bad deployment configuration gives clear errors, not hangs (issue 18).

    python3 tests/python/test_bad_config.py build/bin/beamcast-server build/bin/beamcast

Each case runs the `beamcast` tool as a user would and checks that it exits
non-zero within a bound, with an error that names the problem:
  1. a server address where nothing listens (render, load): refused, retried
     with backoff, then "gave up after 5 tries" naming the address;
  2. an address that accepts but never answers (render --timeout 1, load
     --timeout 1): "timed out (not retried)" after the timeout, not five;
  3. a server that requires a token: a wrong token (render, load) is refused
     as "unauthorized" at once and not retried; no token at all, the same;
     the right token renders;
  4. a balancer whose only server is dead: HAProxy closes each connection,
     the client retries and gives up with an error naming the balancer.
The bounds are the retry policy's worst case (four backoffs of at most
40, 80, 160 and 320 ms: 0.6 s) or the stated timeout, plus 5 s for starting
the tool and its GL-free work on a loaded 2-core machine.
Plain python3; exits 0 only if every check passed.
"""
import os
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from cluster import Cluster, free_port  # noqa: E402
from local_server import start_server, stop_server  # noqa: E402

SCENE = os.path.join(ROOT, "examples", "paper_10sets.json")
SLACK_S = 5.0


def main():
    server_bin, cli_bin = sys.argv[1], sys.argv[2]
    failed = []

    def run(args, bound_s, needles, name):
        with tempfile.TemporaryDirectory() as out:
            t0 = time.monotonic()
            try:
                p = subprocess.run([cli_bin, *args, *(["--out", out] if args[0] == "render" else [])],
                                   capture_output=True, text=True, timeout=bound_s + 30)
                rc, err = p.returncode, p.stderr
            except subprocess.TimeoutExpired:
                rc, err = None, "did not exit (a hang)"
            took = time.monotonic() - t0
        last = [line for line in err.strip().splitlines() if line.startswith("beamcast")][-1:] or [err]
        ok = rc not in (None, 0) and took <= bound_s and all(n in err for n in needles)
        print(("PASS " if ok else "FAIL ") + f"{name}: exit {rc} after {took:.2f} s "
              f"(bound {bound_s:.1f} s): {last[0].strip()}", flush=True)
        if not ok:
            failed.append(name)

    # 1. Nothing listens there.
    closed = free_port()
    addr = f"127.0.0.1:{closed}"
    run(["render", SCENE, "--rig", "orbit:4", "--server", addr], 0.6 + SLACK_S,
        [addr, "Connection refused", "gave up after 5 tries"], "render, nobody listening")
    run(["render", SCENE, "--server", addr], 0.6 + SLACK_S,
        [addr, "Connection refused", "gave up after 5 tries"], "render (one request), nobody listening")
    run(["load", "--server", addr, "--duration", "1", "-q"], 0.6 + SLACK_S,
        [addr, "Connection refused", "gave up after 5 tries"], "load, nobody listening")

    # 2. Accepts (the kernel's backlog) but never answers.
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen(8)
        addr = f"127.0.0.1:{silent.getsockname()[1]}"
        run(["render", SCENE, "--server", addr, "--timeout", "1"], 1 + SLACK_S,
            ["timed out (not retried)"], "render, a server that never answers")
        run(["render", SCENE, "--rig", "orbit:4", "--server", addr, "--timeout", "1"], 1 + SLACK_S,
            ["timed out (not retried)", "every server failed"], "render --rig, a server that never answers")
        run(["load", "--server", addr, "--timeout", "1", "--duration", "1", "-q"], 1 + SLACK_S,
            ["timed out (not retried)"], "load, a server that never answers")

    # 3. Tokens.
    proc, port = start_server([server_bin, "--bind", "127.0.0.1", "--token", "right-token",
                               "--http-port", "0", "--no-demo", "--quiet-requests"])
    try:
        addr = f"127.0.0.1:{port}"
        for args, name in ((["render", SCENE, "--server", addr, "--token", "wrong"], "render"),
                           (["render", SCENE, "--rig", "orbit:4", "--server", addr, "--token", "wrong"],
                            "render --rig"),
                           (["load", "--server", addr, "--token", "wrong", "--duration", "1", "-q"],
                            "load")):
            run(args, SLACK_S, ["unauthorized", "refused hello"], f"{name}, a wrong token")
        run(["render", SCENE, "--server", addr], SLACK_S, ["unauthorized"], "render, no token")
        with tempfile.TemporaryDirectory() as out:
            p = subprocess.run([cli_bin, "render", SCENE, "--server", addr, "--token", "right-token",
                                "--out", out], capture_output=True, text=True, timeout=120)
            good = p.returncode == 0 and any(f.endswith(".png") for f in os.listdir(out))
        print(("PASS " if good else "FAIL ") + f"render, the right token: exit {p.returncode}",
              flush=True)
        if not good:
            failed.append("the right token")
    finally:
        stop_server(proc)

    # 4. A balancer with no live server.
    with tempfile.TemporaryDirectory() as run_dir:
        cluster = Cluster(server_bin, 1, run_dir)
        try:
            cluster.start()
            cluster.wait_status("s1", "UP", 10)
            cluster.procs[0].kill()
            down = cluster.wait_status("s1", "DOWN", 5)
            print(f"  the only server marked down after {down} s", flush=True)
            addr = f"127.0.0.1:{cluster.bcp_port}"
            run(["render", SCENE, "--server", addr], 0.6 + SLACK_S, [addr, "gave up after 5 tries"],
                "render through a balancer with no live server")
        finally:
            cluster.stop()

    print(f"{'FAILED: ' + ', '.join(failed) if failed else 'all checks passed'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
