"""N beamcast-servers behind HAProxy (deploy/haproxy.cfg.in) on loopback, for tests.

Cluster(server_bin, n, run_dir): free ports for each server (BCP1, HTTP),
HAProxy's BCP1 port (bcp_port) and HTTP port (http_port); start() checks the
filled-in configuration with `haproxy -c` and starts everything; stat() reads
HAProxy's admin socket; start_server(i) (re)starts server i on its ports.
"""
import os
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

    def stat(self):
        """{server name: (status, total sessions)} of the BCP1 backend, from `show stat`."""
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
            if row.get("pxname") == "beamcast_bcp1" and row.get("svname", "").startswith("s"):
                out[row["svname"]] = (row["status"], int(row["stot"] or 0))
        return out

    def wait_status(self, name, want, timeout):
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            try:
                if self.stat().get(name, ("", 0))[0].startswith(want):
                    return time.monotonic() - t0
            except OSError:
                pass
            time.sleep(0.01)
        return None

    def stop(self):
        for p in self.procs + [self.haproxy]:
            if p and p.poll() is None:
                p.terminate()
        for p in self.procs + [self.haproxy]:
            if p:
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
