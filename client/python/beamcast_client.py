#!/usr/bin/env python3
"""Beamcast wire-protocol client (protocol/PROTOCOL.md), standard library only.

As a module:
    c = BeamcastClient("127.0.0.1", 7878)
    frames, result = c.render(scene_id="demo")   # frames: list of dicts with "png" bytes
    c.hello(frame_format="raw")    # later frames: dicts with "raw" samples (raw_to_png writes one)
As a script:
    beamcast_client.py --server 127.0.0.1:7878 --scene-id demo --out /tmp/frame.png
    beamcast_client.py --server 127.0.0.1:7878 --scene scene.json --out /tmp/frame.png
"""
import argparse
import base64
import itertools
import json
import random
import socket
import struct
import sys
import threading
import time
import zlib

MAGIC = b"BCP1"
HEADER = struct.Struct(">4sII")  # magic, json_length, binary_length (big-endian)


class ServerError(Exception):
    """The server answered ok: false; code/message/path as in PROTOCOL.md."""

    def __init__(self, error):
        self.code = error.get("code", "")
        self.message = error.get("message", "")
        self.path = error.get("path", "")
        super().__init__(f"[{self.code}] {self.path + ': ' if self.path else ''}{self.message}")


def raw_frame_bytes(width, height, bit_depth):
    """Bytes of a "raw" frame: RGB, rows from the top, 1 byte a sample at bit
    depth 8, 2 little-endian bytes at 16 (PROTOCOL.md, "Frame formats")."""
    return width * height * 3 * (bit_depth // 8)


def unpack_raw_frame(data, fmt, width, height, bit_depth):
    """The raw bytes of a "raw" or "raw_zstd" frame, checked against its size."""
    expected = raw_frame_bytes(width, height, bit_depth)
    if fmt == "raw_zstd":
        try:
            import zstandard  # Debian: python3-zstandard; not in the standard library
        except ImportError as e:
            raise RuntimeError("raw_zstd frames need the zstandard module (Debian: "
                               "python3-zstandard); ask for frame_format \"raw\" instead") from e
        size = zstandard.get_frame_parameters(data).content_size
        if size != expected:
            raise ValueError(f"raw_zstd frame holds {size} bytes, expected {expected}")
        data = zstandard.ZstdDecompressor().decompress(data, max_output_size=expected)
    elif fmt != "raw":
        raise ValueError(f"not a raw frame format: {fmt!r}")
    if len(data) != expected:
        raise ValueError(f"raw frame of {len(data)} bytes, expected {expected}")
    return bytes(data)


def raw_to_png(raw, width, height, bit_depth, level=1):
    """A PNG (RGB, no filter) of a raw frame's bytes, with zlib: lossless."""
    if bit_depth == 16:  # raw is little-endian, PNG big-endian
        swapped = bytearray(raw)
        swapped[0::2], swapped[1::2] = raw[1::2], raw[0::2]
        raw = bytes(swapped)
    stride = width * 3 * (bit_depth // 8)
    lines = b"".join(b"\x00" + raw[y * stride:(y + 1) * stride] for y in range(height))

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) +
            chunk(b"IDAT", zlib.compress(lines, level)) + chunk(b"IEND", b""))


class BeamcastClient:
    def __init__(self, host="127.0.0.1", port=7878, timeout=60.0):
        self.sock = None
        self._ids = itertools.count(1)
        self._kept = {}  # responses that arrived while waiting for another id
        if host is not None:
            self.connect(host, port, timeout)

    def connect(self, host, port, timeout=60.0):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        # Requests are small and latency is measured: do not let Nagle delay them.
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def close(self):
        if self.sock:
            self.sock.close()
            self.sock = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # --- framing ---
    def send(self, method, params=None, request_id=None):
        """Writes one request frame; returns its id (pipelining: receive later)."""
        rid = next(self._ids) if request_id is None else request_id
        req = {"id": rid, "method": method}
        if params is not None:
            req["params"] = params
        body = json.dumps(req, separators=(",", ":")).encode()
        self.sock.sendall(HEADER.pack(MAGIC, len(body), 0) + body)
        return rid

    def _read_exact(self, n):
        chunks = bytearray()
        while len(chunks) < n:
            got = self.sock.recv(min(n - len(chunks), 1 << 20))
            if not got:
                raise ConnectionError("server closed the connection")
            chunks += got
        return bytes(chunks)

    def receive(self):
        """Reads the next frame: (response dict, binary bytes)."""
        magic, json_len, bin_len = HEADER.unpack(self._read_exact(HEADER.size))
        if magic != MAGIC:
            raise ConnectionError(f"not a Beamcast frame (magic {magic!r})")
        msg = json.loads(self._read_exact(json_len))
        return msg, self._read_exact(bin_len)

    def receive_for(self, rid):
        """The response to `rid`; others are kept. A null id (the server could not
        read the request's id) is returned too: it can match nothing else."""
        if rid in self._kept:
            return self._kept.pop(rid)
        while True:
            msg, binary = self.receive()
            if msg.get("id") == rid or msg.get("id") is None:
                return msg, binary
            self._kept[msg.get("id")] = (msg, binary)

    def call(self, method, params=None):
        """send + receive_for; returns (result, binary) or raises ServerError."""
        msg, binary = self.receive_for(self.send(method, params))
        if not msg.get("ok"):
            raise ServerError(msg.get("error", {}))
        return msg.get("result", {}), binary

    # --- methods ---
    def hello(self, client="beamcast-py/0.1.0", frame_format=None):
        """frame_format "raw" or "raw_zstd": this connection's frames come as
        samples (frames then have "raw" bytes instead of "png")."""
        params = {"protocol": 1, "client": client}
        if frame_format is not None:
            params["frame_format"] = frame_format
        return self.call("hello", params)[0]

    def ping(self, payload=None):
        return self.call("ping", payload if payload is not None else {})[0]

    def stats(self):
        return self.call("stats")[0]

    def scene_put(self, scene_id, scene):
        return self.call("scene.put", {"scene_id": scene_id, "scene": scene})[0]

    def render(self, scene=None, scene_id=None, encoding="binary", cameras=None, output=None):
        """Returns (frames, result); each frame is the server's dict plus "png" bytes
        (a "raw" or "raw_zstd" frame: "raw", its unpacked bytes; raw_to_png makes a PNG),
        result["client_e2e_ms"] is the client-measured wall time of the request."""
        if (scene is None) == (scene_id is None):
            raise ValueError("give exactly one of scene, scene_id")
        params = {"scene": scene} if scene is not None else {"scene_id": scene_id}
        params["encoding"] = encoding
        if cameras is not None:
            params["cameras"] = cameras
        if output is not None:
            params["output"] = output
        t0 = time.perf_counter()
        result, binary = self.call("render", params)
        result["client_e2e_ms"] = (time.perf_counter() - t0) * 1000.0
        frames = []
        for f in result["frames"]:
            f = dict(f)
            if "attachment" in f:
                off, n = f["attachment"]["offset"], f["attachment"]["length"]
                if off + n > len(binary):
                    raise ConnectionError(f"frame {f['camera']}: attachment outside binary part")
                data = binary[off:off + n]
            else:
                data = base64.b64decode(f["data_base64"], validate=True)
            fmt = f.get("format", "png")
            if fmt in ("raw", "raw_zstd"):
                f["raw"] = unpack_raw_frame(data, fmt, f["width"], f["height"],
                                            f.get("bit_depth", 8))
            else:
                f["png"] = data
            frames.append(f)
        return frames, result



class RetryBudget:
    """Retries allowed as a share of requests (a token bucket): every request
    earns `ratio` of a retry, a retry spends one, and at most `burst` are
    saved up. With ratio 0.1 a failing cluster sees at most ~1.1 requests
    for every request the callers make, not a storm of retries."""

    def __init__(self, ratio=0.1, burst=10.0):
        self.ratio, self.burst = ratio, burst
        self.tokens = burst
        self.lock = threading.Lock()

    def on_request(self):
        with self.lock:
            self.tokens = min(self.burst, self.tokens + self.ratio)

    def try_spend(self):
        with self.lock:
            if self.tokens >= 1.0 - 1e-9:  # ten requests' 0.1 sum to 0.999...
                self.tokens -= 1.0
                return True
            return False


class ResilientClient:
    """A client for a server or a load balancer in front of several
    (docs/deploy.md): idempotent requests (render, ping, scene.put) are sent
    again on a new connection when the connection drops or cannot be made
    (not when an answer times out: that is raised at once),
    after an exponential backoff with full jitter (base_s x 2^attempt,
    capped at cap_s), while the shared RetryBudget allows; a render by
    scene_id that lands on a server without the scene (unknown_scene) puts
    the scene again, from the content this client stored, and renders once
    more. Counts requests, retries and re-puts. One connection at a time,
    not thread-safe: one per thread, sharing a budget."""

    RETRIABLE = (ConnectionError, OSError, struct.error)

    def __init__(self, host, port, timeout=60.0, budget=None, base_s=0.02, cap_s=1.0,
                 max_attempts=5, rng=None):
        self.host, self.port, self.timeout = host, port, timeout
        self.budget = budget if budget is not None else RetryBudget()
        self.base_s, self.cap_s, self.max_attempts = base_s, cap_s, max_attempts
        self.rng = rng if rng is not None else random.Random()
        self.client = None
        self.scenes = {}  # scene_id -> scene, for re-puts
        self.requests = self.retries = self.reputs = 0

    def close(self):
        if self.client:
            self.client.close()
            self.client = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _attempt(self, fn):
        """fn(client) on a connection (opened if need be), with retries."""
        self.requests += 1
        self.budget.on_request()
        attempt = 0
        while True:
            try:
                if self.client is None:
                    self.client = BeamcastClient(self.host, self.port, self.timeout)
                return fn(self.client)
            except socket.timeout:
                # No answer within the deadline: a retry would wait as long
                # again (and run a slow render twice); a hung server is taken
                # out by the balancer, which cuts the connection: that drop
                # is retried.
                self.close()
                raise
            except self.RETRIABLE:
                self.close()
                attempt += 1
                if attempt >= self.max_attempts or not self.budget.try_spend():
                    raise
                self.retries += 1
                time.sleep(self.rng.uniform(0, min(self.cap_s, self.base_s * 2 ** attempt)))

    def ping(self, payload=None):
        return self._attempt(lambda c: c.ping(payload))

    def scene_put(self, scene_id, scene):
        self.scenes[scene_id] = scene
        return self._attempt(lambda c: c.scene_put(scene_id, scene))

    def render(self, scene=None, scene_id=None, **kw):
        def go(c):
            try:
                return c.render(scene=scene, scene_id=scene_id, **kw)
            except ServerError as e:
                if e.code != "unknown_scene" or scene_id not in self.scenes:
                    raise
                self.reputs += 1
                c.scene_put(scene_id, self.scenes[scene_id])
                return c.render(scene_id=scene_id, **kw)
        return self._attempt(go)

def parse_server(text):
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"--server {text!r}: expected HOST:PORT with PORT in 1..65535")
    return host.strip("[]"), int(port)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Render on a beamcast-server, save the first frame")
    ap.add_argument("--server", default="127.0.0.1:7878", help="HOST:PORT")
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--scene", help="scene JSON file, sent inline")
    src.add_argument("--scene-id", help="a scene stored on the server (e.g. demo)")
    ap.add_argument("--out", default="frame.png", help="where the first frame's PNG goes")
    ap.add_argument("--encoding", choices=["binary", "base64"], default="binary")
    ap.add_argument("--frame-format", choices=["png", "raw", "raw_zstd"], default="png",
                    help="raw, raw_zstd: the server sends samples, the PNG is written here")
    args = ap.parse_args(argv)
    try:
        host, port = parse_server(args.server)
    except ValueError as e:
        ap.error(str(e))
    scene = None
    if args.scene:
        with open(args.scene) as f:
            scene = json.load(f)
    try:
        with BeamcastClient(host, port) as c:
            if args.frame_format != "png":
                c.hello(frame_format=args.frame_format)
            frames, result = c.render(scene=scene, scene_id=args.scene_id, encoding=args.encoding)
            first = frames[0]
            if "raw" in first:
                first["png"] = raw_to_png(first["raw"], first["width"], first["height"],
                                          first.get("bit_depth", 8))
    except ServerError as e:
        print(f"server error {e}", file=sys.stderr)
        return 2
    except (OSError, ValueError, RuntimeError) as e:
        print(f"beamcast_client: {args.server}: {e}", file=sys.stderr)
        return 1
    with open(args.out, "wb") as f:
        f.write(frames[0]["png"])
    t = result.get("timings", {})
    e2e = result["client_e2e_ms"]
    for fr in frames:
        print(f"{fr['camera']:<20} {fr['width']}x{fr['height']} gpu {fr.get('gpu_ms', 0):.3f} ms "
              f"read-back {fr.get('readback_ms', 0):.2f} ms encode {fr.get('encode_ms', 0):.2f} ms")
    print(f"server: queue {t.get('queue_ms', 0):.2f} render {t.get('render_ms', 0):.2f} "
          f"encode {t.get('encode_ms', 0):.2f} total {t.get('server_ms', 0):.2f} ms; "
          f"client end-to-end {e2e:.2f} ms, network {e2e - t.get('server_ms', 0):.2f} ms")
    print(f"wrote {args.out} ({frames[0]['camera']}, {len(frames[0]['png'])} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
