"""N beamcast-servers behind HAProxy (deploy/haproxy.cfg.in) on loopback, for tests.

Cluster(server_bin, n, run_dir): free ports for each server (BCP1, HTTP),
HAProxy's BCP1 port (bcp_port) and HTTP port (http_port); start() checks the
filled-in configuration with `haproxy -c` and starts everything; stat() reads
HAProxy's admin socket; start_server(i) (re)starts server i on its ports.

Run as a program it serves tests in other languages (tests/preview/
haproxy_test.mjs): `cluster.py --server BIN [-n N] --run-dir DIR` starts a
cluster, waits until HAProxy has every server up, prints one JSON line
({"bcp_port", "http_port", "haproxy_pid", "servers": [{"bcp", "http", "pid"}]})
and then answers one JSON line per command read from stdin:
  kill I         SIGKILL server I (0-based) -> {"killed": I, "pid"}
  pause I        SIGSTOP server I, a hung server (kill still ends it) -> {"paused": I}
  start I        (re)start server I on its ports -> {"started": I, "pid"}
  stat [BACKEND] -> {"sN": [status, total sessions], ...}
  wait NAME WANT SECS [BACKEND]
                 -> {"seconds": until NAME's status starts with WANT, or null}
  quit           stop everything (so does the end of stdin)
"""
import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from local_server import start_server  # noqa: E402


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    def __init__(self, server_bin, n, run_dir):
        self.server_bin = server_bin
        self.run_dir = run_dir
        self.ports = [(free_port(), free_port()) for _ in range(n)]
        self.procs = [None] * n
        self.haproxy = None
        self.bcp_port = free_port()
        self.http_port = free_port()

    def start_server(self, i):
        port, http = self.ports[i]
        self.procs[i], _ = start_server(
            [self.server_bin, "--bind", "127.0.0.1", "--http-port", str(http), "--no-demo",
             "--quiet-requests", "--render-workers", "1"], port=port)

    def start(self):
        for i in range(len(self.ports)):
            self.start_server(i)
        bcp = "\n".join(f"  server s{i + 1} 127.0.0.1:{p} check port {h}"
                        for i, (p, h) in enumerate(self.ports))
        http = "\n".join(f"  server s{i + 1} 127.0.0.1:{h} check"
                         for i, (p, h) in enumerate(self.ports))
        with open(os.path.join(ROOT, "deploy", "haproxy.cfg.in")) as f:
            text = f.read()
        for k, v in {"@RUN_DIR@": self.run_dir, "@BIND@": "127.0.0.1",
                     "@BCP_PORT@": str(self.bcp_port), "@HTTP_PORT@": str(self.http_port),
                     "@BCP_SERVERS@": bcp, "@HTTP_SERVERS@": http}.items():
            text = text.replace(k, v)
        cfg = os.path.join(self.run_dir, "haproxy.cfg")
        with open(cfg, "w") as f:
            f.write(text)
        check = subprocess.run(["haproxy", "-c", "-f", cfg], capture_output=True, text=True)
        if check.returncode != 0:
            raise RuntimeError("haproxy -c refused the configuration:\n" + check.stdout +
                               check.stderr)
        self.haproxy = subprocess.Popen(["haproxy", "-f", cfg, "-db"],
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stat(self, backend="beamcast_bcp1"):
        """{server name: (status, total sessions)} of a backend (the BCP1 one by
        default; "beamcast_http" for the preview), from `show stat`."""
        with socket.socket(socket.AF_UNIX) as s:
            s.settimeout(2)
            s.connect(os.path.join(self.run_dir, "haproxy.sock"))
            s.sendall(b"show stat\n")
            data = b""
            while True:
                chunk = s.recv(65536)
                if not chunk:
                    break
                data += chunk
        lines = data.decode().splitlines()
        head = lines[0].lstrip("# ").split(",")
        out = {}
        for line in lines[1:]:
            row = dict(zip(head, line.split(",")))
            if row.get("pxname") == backend and row.get("svname", "").startswith("s"):
                out[row["svname"]] = (row["status"], int(row["stot"] or 0))
        return out

    def wait_status(self, name, want, timeout, backend="beamcast_bcp1"):
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            try:
                if self.stat(backend).get(name, ("", 0))[0].startswith(want):
                    return time.monotonic() - t0
            except OSError:
                pass
            time.sleep(0.01)
        return None

    def stop(self):
        for p in self.procs + [self.haproxy]:
            if p and p.poll() is None:
                p.terminate()
                p.send_signal(signal.SIGCONT)  # a paused server acts on SIGTERM once continued
        for p in self.procs + [self.haproxy]:
            if p:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()


def serve(cluster, commands, reply):
    """Obeys the commands of the module docstring until `quit` or their end."""
    for line in commands:
        words = line.split()
        try:
            if not words:
                continue
            if words[0] == "quit":
                return
            if words[0] == "kill":
                i = int(words[1])
                cluster.procs[i].kill()
                cluster.procs[i].wait()
                reply({"killed": i, "pid": cluster.procs[i].pid})
            elif words[0] == "pause":
                i = int(words[1])
                cluster.procs[i].send_signal(signal.SIGSTOP)
                reply({"paused": i})
            elif words[0] == "start":
                i = int(words[1])
                cluster.start_server(i)
                reply({"started": i, "pid": cluster.procs[i].pid})
            elif words[0] == "stat":
                reply(cluster.stat(*words[1:2]))
            elif words[0] == "wait":
                reply({"seconds": cluster.wait_status(words[1], words[2], float(words[3]),
                                                      *words[4:5])})
            else:
                reply({"error": f"unknown command {words[0]!r}"})
        except (IndexError, ValueError, OSError) as e:
            reply({"error": f"{line.strip()!r}: {e}"})


def main():
    ap = argparse.ArgumentParser(
        description="N beamcast-servers behind HAProxy, driven over stdin")
    ap.add_argument("--server", required=True, help="the beamcast-server binary")
    ap.add_argument("-n", type=int, default=2, help="servers (default 2)")
    ap.add_argument("--run-dir", required=True, help="folder for haproxy.cfg and its admin socket")
    args = ap.parse_args()

    def reply(obj):
        print(json.dumps(obj), flush=True)

    cluster = Cluster(args.server, args.n, args.run_dir)
    try:
        cluster.start()
        # An answer on the admin socket means HAProxy has bound its ports too.
        for backend in ("beamcast_bcp1", "beamcast_http"):
            for i in range(args.n):
                if cluster.wait_status(f"s{i + 1}", "UP", 10, backend) is None:
                    raise SystemExit(f"{backend}/s{i + 1} is not UP after 10 s")
        reply({"bcp_port": cluster.bcp_port, "http_port": cluster.http_port,
               "haproxy_pid": cluster.haproxy.pid,
               "servers": [{"bcp": b, "http": h, "pid": p.pid}
                           for (b, h), p in zip(cluster.ports, cluster.procs)]})
        serve(cluster, sys.stdin, reply)
    finally:
        cluster.stop()


if __name__ == "__main__":
    main()
