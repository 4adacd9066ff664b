#!/usr/bin/python3
"""`beamcast load` traffic classes end to end: test_load_mix.py BEAMCAST SERVER.

Starts SERVER on an ephemeral port and runs BEAMCAST load twice with --json:

- the mix (issue 13): one preview-like connection (a camera moving along an
  orbit, quality "auto") next to one batch-like connection (4-camera orbit
  renders, closed loop) for 2 s at small sizes; both classes must report
  frames, no errors, their own latency histogram, every frame decoded and the
  sampled batch frames equal to a local render; the preview class must have
  got the accuracy controller's answers (a first still PNG frame, then
  interactive JPEG frames), which only "quality": "auto" requests get;
- fairness: 2 connections each pipelining 4 single-camera renders for a fixed
  number of requests; the report must list both connections, their requests
  must add up to the total and the max/min ratio must be consistent with the
  per-connection figures.

No speed targets (those are measured by bench/mixed_load.py and recorded in
docs/performance.md). Plain python3; exit status 0 only if all passed.
"""
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "client", "python"))
from checks import check, summary  # noqa: E402 (tests/python/checks.py)
from local_server import start_server, stop_server  # noqa: E402


def run_load(beamcast, port, args):
    proc = subprocess.run([beamcast, "load", "--server", f"127.0.0.1:{port}", "--json", "-q"]
                          + args, capture_output=True, text=True, timeout=300)
    try:
        return proc.returncode, json.loads(proc.stdout), proc.stderr
    except json.JSONDecodeError:
        return proc.returncode, None, proc.stdout[-2000:] + proc.stderr[-2000:]


def test_mix(beamcast, port):
    rc, out, err = run_load(beamcast, port, [
        "--duration", "2", "--preview-connections", "1", "--preview-size", "64",
        "--batch-connections", "1", "--batch-cameras", "4", "--batch-size", "48",
        "--verify-fraction", "0.5"])
    check("mix: exit status 0", rc == 0, err)
    if out is None:
        check("mix: JSON output", False, err)
        return
    check("mix: mode", out.get("mode") == "mix", out.get("mode"))
    classes = {c["name"]: c for c in out.get("classes", [])}
    check("mix: two classes", sorted(classes) == ["batch", "preview"], sorted(classes))
    if sorted(classes) != ["batch", "preview"]:
        return
    for name, c in classes.items():
        check(f"{name}: frames", c["frames"] > 0, c["frames"])
        check(f"{name}: no errors", c["requests"]["errors"] == 0 and not c["errors_by_code"],
              c["errors_by_code"])
        lat = c["latency_ms"]
        check(f"{name}: own latency histogram", lat["count"] == c["requests"]["ok"]
              and 0 < lat["p50"] <= lat["p90"] <= lat["p99"] <= lat["max"], lat)
        check(f"{name}: one connection", len(c["per_connection"]) == 1, c["per_connection"])
    p, b = classes["preview"], classes["batch"]
    check("preview: quality auto, one camera", p["quality"] == "auto"
          and p["cameras_per_request"] == 1 and p["frames"] == p["requests"]["ok"], p)
    # The controller's first answer on a connection is a still (PNG) frame; the
    # camera then moves every frame, so the rest are interactive JPEG frames.
    pv = p.get("preview", {})
    check("preview: a still frame first, then interactive ones",
          pv.get("still_frames", 0) >= 1 and (p["frames"] < 2 or pv.get("jpeg_frames", 0) >= 1),
          pv)
    check("preview: frames by level add up",
          sum(pv.get("frames_by_level", {}).values()) == p["frames"], pv)
    check("batch: 4 frames per request", b["frames"] == 4 * b["requests"]["ok"], b)
    check("batch: no quality report", "preview" not in b, b.keys())
    check("totals are the classes' sum", out["frames"] == p["frames"] + b["frames"]
          and out["requests"]["ok"] == p["requests"]["ok"] + b["requests"]["ok"],
          (out["frames"], p["frames"], b["frames"]))
    v = out["verify"]
    check("mix: every frame decoded, sampled batch frames match a local render",
          v["all_frames_correct"] and v["decoded"] == out["frames"], v)


def test_fairness(beamcast, port):
    rc, out, err = run_load(beamcast, port, [
        "-c", "2", "--pipeline", "4", "--cameras", "1", "--size", "32", "--requests", "40",
        "--verify-fraction", "0"])
    check("fairness: exit status 0", rc == 0, err)
    if out is None:
        check("fairness: JSON output", False, err)
        return
    classes = out.get("classes", [])
    check("fairness: one class", len(classes) == 1 and classes[0]["name"] == "load", classes)
    if len(classes) != 1:
        return
    c = classes[0]
    pc = c["per_connection"]
    check("fairness: both connections listed", len(pc) == 2, pc)
    check("fairness: pipeline recorded", c["pipeline"] == 4, c["pipeline"])
    check("fairness: requests add up", sum(x["requests"] for x in pc) == 40
          and c["requests"]["ok"] == 40, pc)
    check("fairness: every connection served", all(x["frames"] > 0 for x in pc), pc)
    fps = [x["frames_per_s"] for x in pc]
    ratio = c["fairness_max_over_min"]
    check("fairness: max/min matches the per-connection figures",
          ratio is not None and abs(ratio - max(fps) / min(fps)) < 1e-9, (ratio, fps))


def main():
    beamcast, server = sys.argv[1], sys.argv[2]
    proc, port = start_server([server, "--http-port", "0"])
    try:
        test_mix(beamcast, port)
        test_fairness(beamcast, port)
    finally:
        stop_server(proc)
    return summary()


if __name__ == "__main__":
    sys.exit(main())
