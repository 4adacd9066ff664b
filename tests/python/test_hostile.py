#!/usr/bin/env python3
"""Hostile and edge-case clients against the real beamcast-server binary
(issue 19): one check per defect found by a client written from PROTOCOL.md
alone, each of which failed on the server before the fix.

    python3 tests/python/test_hostile.py build/bin/beamcast-server [NAME ...]

Each check starts its own server (--port 0 --http-port 0, the limits it needs)
and stops it with SIGTERM. Standard library only: a BCP1 client and a minimal
WebSocket client (RFC 6455, masked text frames) are below. Prints one line per
check and "N passed, M failed"; exits 0 only if everything passed. NAMEs pick
checks by substring.
"""
import base64
import json
import os
import re
import select
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
import traceback

SERVER = None  # path of beamcast-server, from argv

SMALL_SCENE = {
    "beams": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "density": "linear"}],
    "cameras": [{"name": "c", "position": [0, 0, 4], "target": [0, 0, 0],
                 "width": 16, "height": 16}],
}


class Server:
    """beamcast-server on free ports; `port`, `http_port`, `pid`."""

    def __init__(self, *args):
        self.proc = subprocess.Popen(
            [SERVER, "--port", "0", "--http-port", "0", "--quiet-requests", *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.stderr = []
        first = self.proc.stdout.readline()
        m = re.search(r"listening on [^ ]*:(\d+)", first)
        if not m:
            err = self.proc.stderr.read()
            raise RuntimeError(f"server did not start: {first!r} {err!r}")
        self.port = int(m.group(1))
        second = self.proc.stdout.readline()
        self.http_port = int(re.search(r":(\d+)/", second).group(1))
        self.pid = self.proc.pid
        threading.Thread(target=self._drain, daemon=True).start()

    def _drain(self):
        for line in self.proc.stderr:
            self.stderr.append(line)

    def alive(self):
        return self.proc.poll() is None

    def status_mib(self, field):
        """A memory field of /proc/PID/status in MiB: VmRSS (resident), VmHWM (peak)."""
        with open(f"/proc/{self.pid}/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) / 1024.0
        raise RuntimeError(f"no {field}")

    def rss_mib(self):
        return self.status_mib("VmRSS")

    def stop(self):
        if self.alive():
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        self.stop()
        # A clean SIGTERM shutdown exits 0; under ASan, LeakSanitizer makes a
        # leak a non-zero exit here.
        if exc_type is None:
            assert self.proc.returncode == 0, (
                f"server exited {self.proc.returncode}: {''.join(self.stderr[-20:])}")


def recv_exact(sock, n):
    """Exactly n bytes from `sock`; EOFError if the server closes first."""
    out = b""
    while len(out) < n:
        chunk = sock.recv(n - len(out))
        if not chunk:
            raise EOFError("connection closed by the server")
        out += chunk
    return out


class Bcp:
    """A blocking BCP1 connection."""

    def __init__(self, port, timeout=30.0):
        self.s = socket.create_connection(("127.0.0.1", port), timeout=timeout)

    def send_text(self, text):
        b = text if isinstance(text, bytes) else text.encode()
        self.s.sendall(b"BCP1" + struct.pack(">II", len(b), 0) + b)

    def _exact(self, n):
        return recv_exact(self.s, n)

    def recv(self):
        h = self._exact(12)
        assert h[:4] == b"BCP1", h
        jl, bl = struct.unpack(">II", h[4:])
        body = self._exact(jl + bl)
        return json.loads(body[:jl]), body[jl:]

    def call(self, obj):
        self.send_text(json.dumps(obj))
        return self.recv()[0]

    def closed_within(self, seconds):
        """True if the server closes the connection within `seconds` (reads EOF)."""
        self.s.settimeout(seconds)
        try:
            while True:
                if not self.s.recv(4096):
                    return True
        except socket.timeout:
            return False
        except ConnectionResetError:
            return True

    def close(self):
        self.s.close()


class Ws:
    """A minimal WebSocket client for /ws: masked text frames, reads whole messages."""

    def __init__(self, port, timeout=30.0):
        self.s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        key = base64.b64encode(os.urandom(16)).decode()
        self.s.sendall((f"GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"
                        f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                        f"Sec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.s.recv(1)
            if not chunk:
                raise EOFError("no upgrade response")
            head += chunk
        assert head.startswith(b"HTTP/1.1 101"), head

    def send_text(self, text):
        payload = text.encode() if isinstance(text, str) else text
        n = len(payload)
        if n < 126:
            hdr = struct.pack(">BB", 0x81, 0x80 | n)
        elif n < 65536:
            hdr = struct.pack(">BBH", 0x81, 0x80 | 126, n)
        else:
            hdr = struct.pack(">BBQ", 0x81, 0x80 | 127, n)
        mask = os.urandom(4)
        # XOR with the mask, 4 bytes at a time through int arithmetic (fast enough for MBs).
        reps = (n + 3) // 4
        m = int.from_bytes(mask * reps, "big")
        body = (int.from_bytes(payload.ljust(reps * 4, b"\0"), "big") ^ m).to_bytes(reps * 4, "big")[:n]
        self.s.sendall(hdr + mask + body)

    def _exact(self, n):
        return recv_exact(self.s, n)

    def recv(self):
        """(opcode, payload) of the next whole message; pings are skipped."""
        data, opcode = b"", None
        while True:
            b0, b1 = self._exact(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._exact(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._exact(8))[0]
            payload = self._exact(n)
            op = b0 & 0x0F
            if op == 9 or op == 10:
                continue
            if op == 8:
                raise EOFError(f"close frame {payload[:2].hex()}")
            if opcode is None:
                opcode = op
            data += payload
            if b0 & 0x80:
                return opcode, data

    def call_text(self, text):
        self.send_text(text)
        op, data = self.recv()
        assert op == 1, op
        return json.loads(data)

    def close(self):
        self.s.close()


def expect_error(reply, code, path=None, rid=None):
    assert reply.get("ok") is False, f"expected error {code}, got {json.dumps(reply)[:300]}"
    e = reply["error"]
    assert e["code"] == code, f"expected {code}, got {e}"
    if path is not None:
        assert e["path"] == path, f"expected path {path!r}, got {e['path']!r} ({e['message']})"
    if rid is not None:
        assert reply["id"] == rid, f"expected id {rid!r}, got {reply['id']!r}"
    assert "json.exception" not in e["message"], e["message"]
    return e


def deep_objects(levels):
    return '{"id":"d","method":"ping","params":' + '{"a":' * levels + "1" + "}" * levels + "}"


def deep_arrays(levels):
    return '{"id":"d","method":"ping","params":{"x":' + "[" * levels + "]" * levels + "}}"


def settle_rss(srv, seconds=2.0):
    """The server's RSS once it has been quiet for a moment (the lowest of a few samples)."""
    best = srv.rss_mib()
    end = time.time() + seconds
    while time.time() < end:
        time.sleep(0.2)
        best = min(best, srv.rss_mib())
    return best


# ---- Defect 1: deep nesting (remote crash before authentication) -----------------

def test_deep_nesting_tcp_and_ws_on_token_server_before_hello():
    token = "t0ken-for-the-test"
    with Server("--token", token) as srv:
        # Warm up both transports once so lazily allocated buffers are in the baseline.
        c = Bcp(srv.port)
        c.call({"id": 0, "method": "hello", "params": {"token": token}})
        c.close()
        w = Ws(srv.http_port)
        w.call_text(json.dumps({"id": 0, "method": "hello", "params": {"token": token}}))
        w.close()
        base = settle_rss(srv)
        cases = [("objects x60000 (the crash input)", deep_objects(60000)),
                 ("objects x600000 (10x deeper)", deep_objects(600000)),
                 ("arrays x100000", deep_arrays(100000)),
                 ("arrays x1000000 (10x deeper)", deep_arrays(1000000))]
        for transport in ("tcp", "ws"):
            for name, text in cases:
                t0 = time.time()
                if transport == "tcp":
                    c = Bcp(srv.port)
                    c.send_text(text)
                    reply = c.recv()[0]
                else:
                    c = Ws(srv.http_port)
                    reply = c.call_text(text)
                e = expect_error(reply, "limit_exceeded", rid="d")
                assert "max_json_depth" in e["message"], e
                # Still usable, still unauthenticated: a ping is refused, hello passes.
                if transport == "tcp":
                    expect_error(c.call({"id": 2, "method": "ping"}), "unauthorized")
                    ok = c.call({"id": 3, "method": "hello", "params": {"token": token}})
                else:
                    expect_error(c.call_text('{"id":2,"method":"ping"}'), "unauthorized")
                    ok = c.call_text(json.dumps({"id": 3, "method": "hello",
                                                 "params": {"token": token}}))
                assert ok["ok"], ok
                c.close()
                assert srv.alive(), f"server died on {transport} {name}"
                print(f"    {transport} {name}: {len(text)} bytes -> {e['code']} "
                      f"({e['message']}) in {1000 * (time.time() - t0):.0f} ms; path depth "
                      f"{e['path'].count('/')}")
        after = settle_rss(srv)
        print(f"    server RSS: baseline {base:.1f} MiB, after the 8 deep requests {after:.1f} MiB")
        # 8 MiB: the largest request here is 3.6 MB; the server holds it twice
        # while reading (frame buffer and text), so one leaked copy of either
        # would already exceed 4 MiB, and glibc keeps up to a few MiB of
        # trimmed-but-fragmented arena. Anything above 8 MiB is a leak or an
        # untrimmed heap.
        # Under AddressSanitizer (CI's last stage sets ASAN_OPTIONS) freed blocks
        # sit in ASan's 256 MiB quarantine: RSS says nothing about leaks there,
        # and LeakSanitizer checks them when the server exits instead.
        if os.environ.get("ASAN_OPTIONS") is None:
            assert after - base < 8.0, f"RSS grew from {base:.1f} to {after:.1f} MiB"
        else:
            print("    (ASan build: RSS not compared; LeakSanitizer checks at exit)")


def test_depth_limit_is_exact():
    with Server("--max-json-depth", "10") as srv:
        c = Bcp(srv.port)
        # Root object (1), params (2) and 8 objects inside it: depth 10 is accepted...
        c.send_text('{"id":1,"method":"ping","params":' + '{"a":' * 9 + "1" + "}" * 9 + "}")
        ok = c.recv()[0]
        assert ok["ok"], ok
        # ... 11 is refused at the 11th container's path.
        c.send_text('{"id":2,"method":"ping","params":' + '{"a":' * 10 + "1" + "}" * 10 + "}")
        expect_error(c.recv()[0], "limit_exceeded", path="/params" + "/a" * 9, rid=2)
        hello = c.call({"id": 3, "method": "hello"})["result"]
        assert hello["limits"]["max_json_depth"] == 10, hello["limits"]
        assert "max_json_values" in hello["limits"], hello["limits"]


def test_every_method_at_the_default_depth_limit():
    """Echo, merge patch and scene validation walk documents of exactly depth 64."""
    with Server("--no-demo") as srv:
        c = Bcp(srv.port)
        # ping: root (1), params (2), 62 more objects = 64.
        c.send_text('{"id":1,"method":"ping","params":' + '{"a":' * 63 + "1" + "}" * 63 + "}")
        r = c.recv()[0]
        assert r["ok"], r
        echo, depth = r["result"]["echo"], 1
        while isinstance(echo, dict):
            echo, depth = echo["a"], depth + 1
        assert depth == 64, depth  # params and its 62 nested objects came back whole
        c.send_text('{"id":2,"method":"ping","params":' + '{"a":' * 64 + "1" + "}" * 64 + "}")
        expect_error(c.recv()[0], "limit_exceeded", rid=2)
        assert c.call({"id": 3, "method": "scene.put",
                       "params": {"scene_id": "s", "scene": SMALL_SCENE}})["ok"]
        # scene.update: root, params, patch, beams, beams[0] = 5, then k objects in
        # the beam's unknown field "a": k = 59 is depth 64, k = 60 is 65.
        def patch(k):
            beam = '{"type":"sphere","center":[0,0,0],"radius":1,"density":"linear","a":'
            return ('{"id":4,"method":"scene.update","params":{"scene_id":"s","patch":'
                    '{"beams":[' + beam + '{"a":' * k + "1" + "}" * k + "}]}}}")
        c.send_text(patch(59))
        # merged, validated, then refused for the unknown field
        expect_error(c.recv()[0], "unknown_field", path="/params/patch/beams/0/a", rid=4)
        c.send_text(patch(60))
        expect_error(c.recv()[0], "limit_exceeded", rid=4)
        # render: root, params, scene (3), then 61 objects in an unknown field = 64.
        c.send_text('{"id":6,"method":"render","params":{"scene":' +
                    json.dumps(SMALL_SCENE)[:-1] + ',"extra":' + '{"a":' * 60 + "1" + "}" * 60 + "}}}")
        expect_error(c.recv()[0], "unknown_field", path="/params/scene/extra", rid=6)
        assert c.call({"id": 7, "method": "ping"})["ok"]


def test_value_count_limit():
    with Server("--max-json-values", "1000") as srv:
        c = Bcp(srv.port)
        c.send_text('{"id":"v","method":"ping","params":{"x":[' + ",".join(["0"] * 2000) + "]}}")
        e = expect_error(c.recv()[0], "limit_exceeded", rid="v")
        assert "max_json_values" in e["message"], e
        assert c.call({"id": 1, "method": "ping", "params": {"x": list(range(100))}})["ok"]


# ---- Defect 2: max_width / max_height vs default sizes ----------------------------

def test_default_camera_sizes_obey_max_width():
    with Server("--max-width", "256", "--no-demo") as srv:
        c = Bcp(srv.port)
        for cam, path in [({}, "/params/cameras/0"),
                          ({"rig": "orbit", "count": 1}, "/params/cameras/0"),
                          ({"rig": "cubemap"}, "/params/cameras/0")]:
            r = c.call({"id": 1, "method": "render",
                        "params": {"scene": SMALL_SCENE, "cameras": [cam]}})
            e = expect_error(r, "limit_exceeded", path=path)
            assert "max_width" in e["message"], e
        # An explicit size within the limit renders at that size.
        r = c.call({"id": 2, "method": "render",
                    "params": {"scene": SMALL_SCENE, "cameras": [{"width": 200, "height": 100}]}})
        assert r["ok"] and r["result"]["frames"][0]["width"] == 200, r
        # A scene's own camera with the default width.
        scene = dict(SMALL_SCENE, cameras=[{"position": [0, 0, 4], "target": [0, 0, 0]}])
        r = c.call({"id": 3, "method": "render", "params": {"scene": scene}})
        expect_error(r, "limit_exceeded", path="/params/scene/cameras/0")


# ---- Defect 3: a cube map vs max_pixels -------------------------------------------

def test_cubemap_size_checked_at_its_own_field():
    with Server("--max-pixels", "2000", "--no-demo") as srv:
        c = Bcp(srv.port)
        r = c.call({"id": 1, "method": "render",
                    "params": {"scene": SMALL_SCENE, "cameras": [{"rig": "cubemap", "size": 8}]}})
        assert r["ok"], r
        assert len(r["result"]["frames"]) == 6 and r["result"]["frames"][0]["width"] == 8, r
        r = c.call({"id": 2, "method": "render",
                    "params": {"scene": SMALL_SCENE, "cameras": [{"rig": "cubemap", "size": 64}]}})
        e = expect_error(r, "limit_exceeded", path="/params/cameras/0/size")
        assert "max_pixels" in e["message"], e


# ---- Defect 4: atlas size ---------------------------------------------------------

def test_atlas_obeys_frame_limits():
    with Server("--max-pixels", "5000", "--max-width", "100", "--no-demo") as srv:
        c = Bcp(srv.port)
        cams = [{"name": f"c{i}", "position": [0, 0, 4], "target": [0, 0, 0],
                 "width": 60, "height": 60} for i in range(4)]
        # Each camera: 3600 pixels (within 5000); the 2x2 atlas: 120 x 120.
        r = c.call({"id": 1, "method": "render",
                    "params": {"scene": SMALL_SCENE, "cameras": cams, "atlas": True}})
        e = expect_error(r, "limit_exceeded", path="/params/atlas")
        assert "atlas" in e["message"], e
        r = c.call({"id": 2, "method": "render",
                    "params": {"scene": SMALL_SCENE, "cameras": cams[:1], "atlas": True}})
        assert r["ok"], r


# ---- Defect 5: the scene store's byte limit ---------------------------------------

def test_scene_store_bytes_never_exceeded():
    with Server("--max-scene-store-bytes", "1200", "--no-demo") as srv:
        c = Bcp(srv.port)
        big = dict(SMALL_SCENE, beams=[dict(SMALL_SCENE["beams"][0], center=[i, 0, 0])
                                       for i in range(20)])
        assert len(json.dumps(big, separators=(",", ":"))) > 1200
        r = c.call({"id": 1, "method": "scene.put", "params": {"scene_id": "big", "scene": big}})
        e = expect_error(r, "limit_exceeded", path="/params/scene")
        assert "max_scene_store_bytes" in e["message"], e
        r = c.call({"id": 2, "method": "scene.put", "params": {"scene_id": "s", "scene": SMALL_SCENE}})
        assert r["ok"], r
        r = c.call({"id": 3, "method": "scene.update",
                    "params": {"scene_id": "s", "patch": {"beams": big["beams"]}}})
        expect_error(r, "limit_exceeded", path="/params/patch")
        stats = c.call({"id": 4, "method": "stats"})["result"]
        assert stats["scenes"]["bytes"] <= 1200, stats["scenes"]
        assert stats["scenes"]["count"] == 1, stats["scenes"]


# ---- Defect 6: slow headers and the idle timeout ----------------------------------

def padded_ping(rid, size):
    """A ping request of exactly `size` bytes."""
    head, tail = '{"id":"%s","method":"ping","params":{"pad":"' % rid, '"}}'
    return (head + "x" * (size - len(head) - len(tail)) + tail).encode()


def test_request_memory_budget():
    # 40 bytes of budget per message byte (server/memory.hpp): 4 MB admits
    # one message of up to 100 000 bytes.
    with Server("--no-demo", "--max-request-memory-bytes", "4000000") as srv:
        c = Bcp(srv.port)
        c.send_text(padded_ping("big", 150_000))
        e = expect_error(c.recv()[0], "limit_exceeded", rid=None)
        assert "max_request_memory_bytes = 4000000" in e["message"], e
        assert c.call({"id": 1, "method": "ping"})["ok"]  # the connection carries on

        # A message whose body is still arriving holds 60 000 x 40 bytes...
        a = Bcp(srv.port)
        body = padded_ping("a", 60_000)
        a.s.sendall(b"BCP1" + struct.pack(">II", len(body), 0) + body[:1000])
        time.sleep(0.5)
        # ...so another like it does not fit, over TCP or WebSocket...
        b = Bcp(srv.port)
        b.send_text(padded_ping("b", 60_000))
        e = expect_error(b.recv()[0], "busy", rid=None)
        assert "max_request_memory_bytes = 4000000" in e["message"], e
        w = Ws(srv.http_port)
        e = expect_error(w.call_text(padded_ping("w", 60_000)), "busy", rid=None)
        assert "max_request_memory_bytes" in e["message"], e
        assert b.call({"id": 2, "method": "ping"})["ok"]  # small ones still do
        # ...until the first is complete and answered.
        a.s.sendall(body[1000:])
        assert a.recv()[0]["id"] == "a"
        b.send_text(padded_ping("b2", 60_000))
        r = b.recv()[0]
        assert r.get("ok") and r["id"] == "b2", str(r)[:200]
        assert w.call_text(padded_ping("w2", 60_000))["ok"]
        for conn in (a, b, c, w):
            conn.close()


def test_read_timeout_does_not_count_the_servers_parse_time():
    # Two 10 MB pings sent at once to one network thread: while it parses and
    # answers one (over a second here), the other's bytes stop arriving (the
    # socket buffers are full) and its read_timeout_ms passes in wall time.
    # That time is the server's, not the client's (MessageClock,
    # server_core.hpp): both must be answered. Before, the second timed out.
    # The read timeout is well under one ping's handling, so counting the
    # server's time would time the second out: over a second in the release
    # build against 600 ms; 14.3 s under ASan (one ping alone, idle machine)
    # against 3000 ms. Under ASan the longer timeout leaves room for the
    # client thread itself to be held off the CPU by the other test running
    # beside it (CI runs two at a time): with 600 ms it once read "timeout"
    # for b there while passing alone.
    keys = ",".join(f'"k{i}":{i % 10}' for i in range(900_000))
    read_timeout = "600" if os.environ.get("ASAN_OPTIONS") is None else "3000"
    with Server("--no-demo", "--read-timeout-ms", read_timeout, "--network-threads", "1",
                "--max-request-memory-bytes", "4000000000") as srv:
        answers = {}

        def one(rid):
            try:
                c = Bcp(srv.port, timeout=120)
                c.send_text('{"id":"%s","method":"ping","params":{%s}}' % (rid, keys))
                r = c.recv()[0]
                answers[rid] = "ok" if r.get("ok") else r["error"]["code"]
                c.close()
            except OSError as e:
                answers[rid] = type(e).__name__
        threads = [threading.Thread(target=one, args=(rid,)) for rid in ("a", "b")]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert answers == {"a": "ok", "b": "ok"}, answers


def test_partial_header_times_out_with_read_timeout():
    with Server("--read-timeout-ms", "1000", "--no-demo") as srv:
        c = Bcp(srv.port)
        t0 = time.time()
        c.s.sendall(b"BCP1")
        c.s.settimeout(5.0)
        reply = c.recv()[0]
        took = time.time() - t0
        expect_error(reply, "timeout")
        assert 0.9 <= took < 3.0, f"timeout after {took:.2f} s (read_timeout_ms 1000)"
        assert c.closed_within(3.0)


def test_partial_websocket_message_times_out():
    with Server("--read-timeout-ms", "1000", "--no-demo") as srv:
        w = Ws(srv.http_port)
        assert w.call_text('{"id":1,"method":"ping"}')["ok"]
        # A text frame announcing 100 bytes, of which 10 arrive.
        mask = b"\0\0\0\0"
        w.s.sendall(struct.pack(">BB", 0x81, 0x80 | 100) + mask + b'{"id":2,"m')
        t0 = time.time()
        op, data = w.recv()
        took = time.time() - t0
        expect_error(json.loads(data), "timeout")
        assert 0.9 <= took < 3.0, f"timeout after {took:.2f} s (read_timeout_ms 1000)"


def test_slow_but_steady_sender_is_not_idle():
    with Server("--idle-timeout-ms", "500", "--read-timeout-ms", "15000", "--no-demo") as srv:
        c = Bcp(srv.port)
        body = b'{"id":1,"method":"ping"}'
        frame = b"BCP1" + struct.pack(">II", len(body), 0) + body
        for b in frame:  # one byte every 150 ms: never 500 ms without a byte
            c.s.sendall(bytes([b]))
            time.sleep(0.15)
        c.s.settimeout(5.0)
        reply = c.recv()[0]
        assert reply["ok"] and reply["id"] == 1, reply
        # With nothing arriving, idle_timeout_ms closes it.
        assert c.closed_within(3.0)


# ---- Defect 7: a number beyond double keeps the id and names the field ------------

def test_overflowing_number_keeps_id_and_path():
    with Server("--no-demo") as srv:
        c = Bcp(srv.port)
        scene = json.dumps(SMALL_SCENE).replace('"radius": 1', '"radius": 1e999')
        c.send_text('{"id":"nf","method":"render","params":{"scene":' + scene + "}}")
        e = expect_error(c.recv()[0], "not_finite", path="/params/scene/beams/0/radius", rid="nf")
        assert "1e999" in e["message"], e
        # The id after the number is recovered too.
        c.send_text('{"method":"ping","params":{"x":[1,-1e400]},"id":"late"}')
        expect_error(c.recv()[0], "not_finite", path="/params/x/1", rid="late")
        # Syntax errors: the project's words and a position, never the library's text.
        c.send_text('{"id":"s","method":"ping","params":{"x":tru}}')
        e = expect_error(c.recv()[0], "bad_json", path="/params/x", rid="s")
        assert "line 1" in e["message"], e


# ---- Defect 8: token semantics ----------------------------------------------------

def test_token_semantics():
    token = "right-token"
    with Server("--token", token, "--no-demo") as srv:
        c = Bcp(srv.port)
        # protocol 2 with the right token: refused, and not authenticated.
        r = c.call({"id": 1, "method": "hello", "params": {"protocol": 2, "token": token}})
        expect_error(r, "unsupported_protocol")
        expect_error(c.call({"id": 2, "method": "ping"}), "unauthorized")
        # An integer token is named as such, not as missing.
        e = expect_error(c.call({"id": 3, "method": "hello", "params": {"token": 12345}}),
                         "unauthorized", path="/params/token")
        assert "string" in e["message"], e
        assert c.call({"id": 4, "method": "hello", "params": {"token": token}})["ok"]
        # A wrong token is refused on an authenticated connection too.
        expect_error(c.call({"id": 5, "method": "hello", "params": {"token": "wrong"}}),
                     "unauthorized", path="/params/token")
        assert c.call({"id": 6, "method": "ping"})["ok"]


# ---- Item 9: smaller mismatches with the spec ------------------------------------

def test_spec_mismatches():
    with Server("--no-demo") as srv:
        c = Bcp(srv.port)
        # Integral float ids and protocol numbers, as the scene format accepts them.
        r = c.call({"id": 7.0, "method": "hello", "params": {"protocol": 1.0}})
        assert r["ok"] and r["id"] == 7, r
        # An id of 128 characters (not bytes).
        rid = "\u00e9" * 128
        assert c.call({"id": rid, "method": "ping"})["id"] == rid
        expect_error(c.call({"id": "\u00e9" * 129, "method": "ping"}), "bad_request", path="/id")
        # hello and stats refuse unknown params as render does.
        expect_error(c.call({"id": 1, "method": "hello", "params": {"protcol": 1}}),
                     "unknown_field", path="/params/protcol")
        expect_error(c.call({"id": 1, "method": "stats", "params": {"fromat": "json"}}),
                     "unknown_field", path="/params/fromat")
        # params that is not an object: invalid_params.
        expect_error(c.call({"id": 1, "method": "ping", "params": [1]}), "invalid_params",
                     path="/params")
        # JPEG frames report 8 bits whatever the scene's PNG depth.
        scene = dict(SMALL_SCENE, output={"bit_depth": 16})
        r = c.call({"id": 9, "method": "render",
                    "params": {"scene": scene, "quality": "auto", "motion": "moving"}})
        r = c.call({"id": 10, "method": "render",
                    "params": {"scene": scene, "quality": "auto", "motion": "moving"}})
        f = r["result"]["frames"][0]
        assert f["format"] == "jpeg", f  # a moving frame, interactive_format's default
        assert f["bit_depth"] == 8, f
        r = c.call({"id": 11, "method": "render", "params": {"scene": scene}})
        f = r["result"]["frames"][0]
        assert f["format"] == "png" and f["bit_depth"] == 16, f


def test_demo_scene_over_a_limit_is_named_before_listening():
    p = subprocess.run([SERVER, "--port", "0", "--http-port", "-1", "--max-beams", "1"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 1, p
    assert "listening" not in p.stdout, p.stdout
    assert "demo scene" in p.stderr and "--no-demo" in p.stderr, p.stderr


def main():
    global SERVER
    SERVER = sys.argv[1]
    picks = sys.argv[2:]
    tests = [(n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)]
    if picks:
        tests = [(n, f) for n, f in tests if any(p in n for p in picks)]
    passed = failed = 0
    for name, fn in tests:
        t0 = time.time()
        try:
            fn()
            passed += 1
            print(f"PASS {name} ({time.time() - t0:.1f} s)", flush=True)
        except Exception:
            failed += 1
            print(f"FAIL {name} ({time.time() - t0:.1f} s)", flush=True)
            traceback.print_exc()
    print(f"{passed} passed, {failed} failed")
    sys.exit(0 if failed == 0 else 1)


if __name__ == "__main__":
    main()
