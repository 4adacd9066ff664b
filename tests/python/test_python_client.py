#!/usr/bin/env python3
"""End-to-end test of client/python/beamcast_client.py against a real server.

    python3 tests/python/test_python_client.py build/bin/beamcast-server [extra server args]

Starts the server on an ephemeral port (--port 0), runs the checks below, sends
SIGTERM and expects exit status 0 within 15 s. Plain python3, no pytest: prints
"N passed, M failed" and exits 0 only if everything passed.
"""
import os
import signal
import socket
import struct
import subprocess
import sys
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "client", "python"))
from beamcast_client import BeamcastClient, ResilientClient, RetryBudget, ServerError  # noqa: E402
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
             test_bad_scene_names_path, test_pipelined_by_id, test_resilient_client]
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
