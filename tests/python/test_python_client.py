#!/usr/bin/env python3
"""End-to-end test of client/python/beamcast_client.py against a real server.

    python3 tests/python/test_python_client.py build/bin/beamcast-server [extra server args]

Starts the server on an ephemeral port (--port 0), runs the checks below, sends
SIGTERM and expects exit status 0 within 15 s. Plain python3, no pytest: prints
"N passed, M failed" and exits 0 only if everything passed.
"""
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import traceback
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "client", "python"))
import beamcast_client  # noqa: E402
from beamcast_client import (BeamcastClient, ResilientClient, RetryBudget, ServerError,  # noqa: E402
                             raw_to_png)
from local_server import start_server  # noqa: E402

# One sphere beam seen from the front by one 64x64 camera.
TINY_SCENE = {
    "beams": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "density": "linear"}],
    "cameras": [{"name": "tiny", "position": [0, 0, 4], "target": [0, 0, 0],
                 "width": 64, "height": 64}],
}


def png_size(data):
    """(width, height, bit_depth) from the IHDR chunk, after checking the signature."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"not a PNG: starts with {data[:8]!r}"
    assert data[12:16] == b"IHDR", "the first chunk is not IHDR"
    width, height, depth = struct.unpack(">IIB", data[16:25])
    return width, height, depth


def check_frames(frames, result):
    assert frames, "no frames"
    assert len(frames) == len(result["frames"])
    for f in frames:
        w, h, depth = png_size(f["png"])
        assert (w, h) == (f["width"], f["height"]), \
            f"{f['camera']}: IHDR {w}x{h}, response says {f['width']}x{f['height']}"
        assert depth == f.get("bit_depth", 8), f"{f['camera']}: IHDR bit depth {depth}"
    assert "server_ms" in result["timings"], result.get("timings")


def png_samples(data):
    """The sample bytes (16-bit: little-endian, as raw frames) of an RGB PNG
    without interlace: a minimal decoder (IDAT, the five row filters)."""
    w, h, depth = png_size(data)
    pos, idat = 8, b""
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IDAT":
            idat += data[pos + 8:pos + 8 + n]
        pos += 12 + n
    lines, bpp = zlib.decompress(idat), 3 * depth // 8
    stride, out, prev = w * bpp, bytearray(), bytearray(w * bpp)
    for y in range(h):
        ftype, row = lines[y * (stride + 1)], bytearray(lines[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = row[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            p = a + b - c
            pred = [0, a, b, (a + b) // 2,
                    a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c)
                    else b if abs(p - b) <= abs(p - c) else c][ftype]
            row[i] = (row[i] + pred) & 0xFF
        out += row
        prev = row
    if depth == 16:  # PNG is big-endian
        out[0::2], out[1::2] = out[1::2], out[0::2]
    return bytes(out)


def test_raw_frames(c):
    """hello frame_format raw / raw_zstd: the frame's samples equal the PNG's."""
    host, port = c.sock.getpeername()[:2]
    for depth in (8, 16):
        frames, _ = c.render(scene=TINY_SCENE, output={"bit_depth": depth})
        want = png_samples(frames[0]["png"])
        for fmt in ("raw", "raw_zstd"):
            with BeamcastClient(host, port, timeout=120) as rc:
                assert rc.hello(frame_format=fmt)["frame_format"] == fmt
                got, _ = rc.render(scene=TINY_SCENE, output={"bit_depth": depth})
            assert got[0]["format"] == fmt and "png" not in got[0], got[0].keys()
            assert got[0]["raw"] == want, f"{fmt} at {depth} bits differs from the PNG"
            assert png_samples(raw_to_png(got[0]["raw"], 64, 64, depth)) == want


def test_raw_frames_script_and_refusal(c):
    host, port = c.sock.getpeername()[:2]
    base = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"beamcast_raw_{os.getpid()}")
    with open(base + ".json", "w") as f:
        json.dump(TINY_SCENE, f)
    rc = beamcast_client.main(["--server", f"{host}:{port}", "--scene", base + ".json",
                               "--frame-format", "raw_zstd", "--out", base + ".png"])
    assert rc == 0, rc
    with open(base + ".png", "rb") as f:
        written = f.read()
    os.unlink(base + ".png")
    os.unlink(base + ".json")
    frames, _ = c.render(scene=TINY_SCENE)
    assert png_samples(written) == png_samples(frames[0]["png"])
    try:
        c.hello(frame_format="webp")
    except ServerError as e:
        assert (e.code, e.path) == ("invalid_value", "/params/frame_format"), (e.code, e.path)
        return
    raise AssertionError("frame_format webp was accepted")


def test_hello(c):
    r = c.hello()
    assert r["protocol"] == 1, r
    assert "render" in r.get("methods", []), r


def test_ping(c):
    assert c.ping({"n": 7, "s": "x"}) == {"echo": {"n": 7, "s": "x"}}


def test_render_demo_binary(c):
    frames, result = c.render(scene_id="demo")
    check_frames(frames, result)
    assert all("attachment" in f for f in frames), "binary encoding should use attachments"


def test_render_inline_base64(c):
    frames, result = c.render(scene=TINY_SCENE, encoding="base64")
    check_frames(frames, result)
    assert [(f["camera"], f["width"], f["height"]) for f in frames] == [("tiny", 64, 64)]
    assert "data_base64" in frames[0] and "attachment" not in frames[0]


def test_bad_scene_names_path(c):
    bad = {"beams": [{"type": "sphere", "center": [0, 0, 0], "radius": -1}], "cameras": [{}]}
    try:
        c.render(scene=bad)
    except ServerError as e:
        assert e.path == "/params/scene/beams/0/radius", (e.code, e.path)
        return
    raise AssertionError("a negative radius was accepted")


def test_pipelined_by_id(c):
    # Two requests before reading: each answer must be found by its id.
    r_render = c.send("render", {"scene": TINY_SCENE})
    r_ping = c.send("ping", {"k": 1})
    msg, _ = c.receive_for(r_ping)
    assert msg["ok"] and msg["result"] == {"echo": {"k": 1}}, msg
    msg, binary = c.receive_for(r_render)
    assert msg["ok"] and msg["id"] == r_render, msg
    assert len(binary) == msg["result"]["frames"][0]["attachment"]["length"]


def test_resilient_client(c):
    # ResilientClient (docs/deploy.md): a scene gone from the server is put
    # again from the client's copy; a dropped connection is retried on a new
    # one; the budget allows ~10% retries and a burst.
    port = c.sock.getpeername()[1]
    with ResilientClient("127.0.0.1", port, timeout=120) as rc:
        rc.scene_put("resilient", TINY_SCENE)
        c.call("scene.delete", {"scene_id": "resilient"})
        frames, result = rc.render(scene_id="resilient")
        check_frames(frames, result)
        assert (rc.reputs, rc.retries) == (1, 0), (rc.reputs, rc.retries)
        rc.client.sock.shutdown(socket.SHUT_RDWR)  # the connection drops
        frames, result = rc.render(scene_id="resilient")
        check_frames(frames, result)
        assert (rc.reputs, rc.retries, rc.requests) == (1, 1, 3), (rc.reputs, rc.retries)
    b = RetryBudget(ratio=0.1, burst=1.0)
    assert b.try_spend() and not b.try_spend()
    for _ in range(9):
        b.on_request()
    assert not b.try_spend()  # 0.9 of a retry earned
    b.on_request()
    assert b.try_spend()


def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    proc, port = start_server(sys.argv[1:2] + sys.argv[2:], echo=True)
    passed = failed = 0
    tests = [test_hello, test_ping, test_render_demo_binary, test_render_inline_base64,
             test_bad_scene_names_path, test_pipelined_by_id, test_resilient_client,
             test_raw_frames, test_raw_frames_script_and_refusal]
    try:
        with BeamcastClient("127.0.0.1", port, timeout=120) as c:
            for t in tests:
                try:
                    t(c)
                    passed += 1
                    print(f"PASS {t.__name__}")
                except Exception:  # one failure must not hide the others
                    failed += 1
                    print(f"FAIL {t.__name__}\n{traceback.format_exc()}")
        proc.send_signal(signal.SIGTERM)
        try:
            rc = proc.wait(timeout=15)
            if rc == 0:
                passed += 1
                print("PASS sigterm_exits_0")
            else:
                failed += 1
                print(f"FAIL sigterm_exits_0: exit status {rc}")
        except subprocess.TimeoutExpired:
            failed += 1
            print("FAIL sigterm_exits_0: still running 15 s after SIGTERM")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
