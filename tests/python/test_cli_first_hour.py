#!/usr/bin/env python3
"""A new user's commands (issue 40): the CLI against one token-protected server.

    python3 tests/python/test_cli_first_hour.py build/bin/beamcast-server build/bin/beamcast

Checks, each on something the issue found wrong:
  --version; ping, stats and scenes with no --server (BEAMCAST_SERVER) and the
  token from BEAMCAST_TOKEN (render too), refused without it; `scenes` lists
  and `scenes --delete` deletes; `render --server --scene-id demo --rig
  orbit:N` renders the stored scene's orbit, with progress between the first
  and the last frame, and a rig of a file leaves no scene behind; --size and
  --camera; frames named after the scene without --out; CPU reference
  progress; curl on the TCP port gets an HTTP answer naming the HTTP port, and
  ping on the HTTP port an error naming the TCP port; help texts; the run
  and test package sets of scripts/install-deps.sh; curl POSTs
  examples/cornell_box.json to /v1/render (with the token; 401 without it; a
  bad scene 400 with its path).
Frames are 32x32 or smaller but the Cornell box (512x512, about 2 s): about
8 s in all on 2 cores.
"""
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "client", "python"))
from beamcast_client import BeamcastClient, ServerError  # noqa: E402
from checks import check, summary  # noqa: E402

TOKEN = "first-hour-token"


def png_size(path):
    if not os.path.exists(path):
        return None
    with open(path, "rb") as f:
        head = f.read(24)
    return struct.unpack(">II", head[16:24])


def start(server_bin):
    proc = subprocess.Popen([server_bin, "--bind", "127.0.0.1", "--port", "0", "--http-port", "0",
                             "--token", TOKEN], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True)
    lines = []
    reader = threading.Thread(target=lambda: lines.extend([proc.stdout.readline(),
                                                            proc.stdout.readline()]), daemon=True)
    reader.start()
    reader.join(60)
    if len(lines) < 2 or "listening on" not in lines[0]:
        proc.kill()
        raise SystemExit(f"the server did not start: {lines}")
    port = int(lines[0].strip().rsplit(":", 1)[1])
    http_port = int(lines[1].strip().rstrip("/").rsplit(":", 1)[1])
    threading.Thread(target=lambda: [None for _ in proc.stdout], daemon=True).start()
    return proc, port, http_port


def main():
    server_bin, cli = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    proc, port, http_port = start(server_bin)
    env = dict(os.environ, BEAMCAST_SERVER=f"127.0.0.1:{port}", BEAMCAST_TOKEN=TOKEN)
    no_token = {k: v for k, v in env.items() if k != "BEAMCAST_TOKEN"}

    def run(*args, environ=env, cwd=None):
        p = subprocess.run([cli, *args], capture_output=True, text=True, env=environ, cwd=cwd,
                           timeout=120)
        return p.returncode, p.stdout, p.stderr

    try:
        rc, out, _ = run("--version")
        check("--version", rc == 0 and out.startswith("beamcast ") and out.split()[1][0].isdigit(), out)

        # The server and the token from the environment, for every command.
        rc, out, err = run("ping", "-c", "1")
        check("ping with no --server (BEAMCAST_SERVER) and BEAMCAST_TOKEN", rc == 0, err)
        rc, out, err = run("stats")
        check("stats with no --server", rc == 0 and '"connections"' in out, err)
        rc, out, err = run("ping", "-c", "1", environ=no_token)
        check("ping without the token is refused", rc != 0 and "unauthorized" in err, err)
        rc, out, err = run("scenes")
        check("scenes lists the stored demo", rc == 0 and "demo" in out.split(), out + err)

        # scene.get and scene.list on the wire, and their errors' codes and paths.
        with BeamcastClient("127.0.0.1", port, timeout=30) as c:
            c.call("hello", {"protocol": 1, "token": TOKEN})
            got, _ = c.call("scene.get", {"scene_id": "demo"})
            listed, _ = c.call("scene.list")
            errors = []
            for params in ({"scene_id": "nope"}, {}, {"scene_id": "demo", "x": 1}):
                try:
                    c.call("scene.get", params)
                    errors.append(None)
                except ServerError as e:
                    errors.append((e.code, e.path))
            try:
                c.call("scene.list", {"x": 1})
                errors.append(None)
            except ServerError as e:
                errors.append((e.code, e.path))
        check("scene.get returns the stored scene",
              got.get("scene_id") == "demo" and len(got.get("scene", {}).get("beams", [])) > 0)
        check("scene.list lists it", "demo" in listed.get("scenes", []) and listed.get("count", 0) >= 1,
              listed)
        check("scene.get/scene.list errors name code and path",
              errors == [("unknown_scene", "/params/scene_id"), ("missing_field", "/params/scene_id"),
                         ("unknown_field", "/params/x"), ("unknown_field", "/params/x")], errors)

        with tempfile.TemporaryDirectory() as d:
            scene = os.path.join(ROOT, "examples", "paper_1set.json")
            rc, out, err = run("render", scene, "--server", "--size", "24x16", "--out", d)
            check("render --server (alone: BEAMCAST_SERVER) with BEAMCAST_TOKEN and --size",
                  rc == 0 and png_size(os.path.join(d, "view.png")) == (24, 16), err)
            rc, out, err = run("render", scene, "--server", "--out", d, environ=no_token)
            check("render --server without the token is refused", rc != 0 and "unauthorized" in err,
                  err)

            # The stored scene's orbit, streamed: progress moves within the batch.
            rig = os.path.join(d, "rig")
            rc, out, err = run("render", "--server", f"127.0.0.1:{port}", "--scene-id", "demo",
                               "--rig", "orbit:8", "--size", "32x32", "--out", rig)
            frames = sorted(os.listdir(rig)) if os.path.isdir(rig) else []
            steps = [l for l in err.splitlines() if l.startswith("frames ")]
            check("render --server --scene-id demo --rig orbit:8",
                  rc == 0 and len(frames) == 8 and png_size(os.path.join(rig, frames[0])) == (32, 32),
                  err)
            check("its progress moves between the first and the last frame",
                  any(l.startswith("frames ") and not l.startswith(("frames 0/", "frames 8/"))
                      for l in steps), steps)
            rc, out, err = run("render", scene, "--server", f"127.0.0.1:{port}", "--rig", "orbit:2",
                               "--size", "16x16", "--out", os.path.join(d, "rig2"))
            rc2, listed, _ = run("scenes")
            check("render --server --rig deletes the scene it stored",
                  rc == 0 and not any(s.startswith("render-") for s in listed.split()), listed)

            # --camera, and names without --out.
            multi = os.path.join(ROOT, "examples", "multi_camera.json")
            rc, out, err = run("render", multi, "--camera", "top", "--size", "16x16", cwd=d)
            check("render --camera top without --out writes multi_camera_top.png only",
                  rc == 0 and os.path.exists(os.path.join(d, "multi_camera_top.png"))
                  and not os.path.exists(os.path.join(d, "multi_camera_front.png"))
                  and not os.path.exists(os.path.join(d, "top.png")), err + str(os.listdir(d)))
            rc, out, err = run("render", multi, "--camera", "nope", "--out", d)
            check("render --camera nope names the scene's cameras",
                  rc != 0 and "nope" in err and "front" in err and "top" in err, err)

            # The CPU reference's progress.
            rc, out, err = run("render", scene, "--reference", "--size", "16x16", "--out", d)
            check("render --reference prints its progress",
                  rc == 0 and "CPU reference, rows 16/16" in err, err)

        rc, out, err = run("scenes", "--delete", "nope")
        check("scenes --delete of an unknown id fails naming it", rc != 0 and "unknown_scene" in err, err)
        rc, out, err = run("scenes", "--delete", "demo")
        rc2, listed, _ = run("scenes")
        check("scenes --delete demo deletes it", rc == 0 and "demo" not in listed.split(), out + listed)

        # Wrong ports.
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUser-Agent: curl/7.88\r\n\r\n")
            reply = s.makefile("rb").read()  # up to the server's close
        text = reply.decode("utf-8", "replace")
        check("HTTP on the TCP port: a plain HTTP answer naming the HTTP port",
              text.startswith("HTTP/1.1 400") and f"port {http_port}" in text, text)
        rc, out, err = run("ping", "--server", f"127.0.0.1:{http_port}", "-c", "1", environ=no_token)
        check("ping on the HTTP port: an error naming the TCP port",
              rc != 0 and "HTTP port" in err and f"TCP port {port}" in err, err)

        # POST /v1/render with curl, the guide's command (issue 40's must-show),
        # with the server's token; without it 401; a bad scene 400 with its path.
        url = f"http://127.0.0.1:{http_port}/v1/render"
        cornell = os.path.join(ROOT, "examples", "cornell_box.json")
        with tempfile.TemporaryDirectory() as d:
            x_png = os.path.join(d, "x.png")
            p = subprocess.run(["curl", "-sf", "-H", f"Authorization: Bearer {TOKEN}", "--data-binary",
                                f"@{cornell}", url, "-o", x_png], capture_output=True, timeout=120)
            check("curl -sf --data-binary @examples/cornell_box.json .../v1/render -o x.png",
                  p.returncode == 0 and png_size(x_png) == (512, 512), (p.returncode, png_size(x_png)))
        p = subprocess.run(["curl", "-s", "-w", "\n%{http_code}", "--data-binary", f"@{cornell}", url],
                           capture_output=True, text=True, timeout=60)
        check("curl without the token: 401 and the JSON error",
              p.stdout.endswith("\n401") and '"code":"unauthorized"' in p.stdout, p.stdout)
        p = subprocess.run(["curl", "-s", "-w", "\n%{http_code}", "-H", f"Authorization: Bearer {TOKEN}",
                            "--data-binary", '{"beams": [{"type": "sphere", "radius": -1}]}', url],
                           capture_output=True, text=True, timeout=60)
        check("curl with a bad scene: 400, the code and the path into the body",
              p.stdout.endswith("\n400") and '"path":"/beams/0/radius"' in p.stdout, p.stdout)
        p = subprocess.run(["curl", "-s", "-w", "\n%{http_code}", "-H", f"Authorization: Bearer {TOKEN}",
                            "--data-binary", '{"scene_id": "nope"}', url],
                           capture_output=True, text=True, timeout=60)
        check("curl with an unknown scene id: 404 unknown_scene",
              p.stdout.endswith("\n404") and "unknown_scene" in p.stdout, p.stdout)
    finally:
        proc.terminate()
        proc.wait(timeout=30)

    # Help texts.
    for args, bad in ((["bench", "accuracy", "--help"], "{false}"),
                      (["bench", "views", "--help"], "{false}"),
                      (["bench", "volumes", "--help"], "seed's"),
                      (["bench", "fog", "--help"], "seed's")):
        rc, out, _ = run(*args)
        check(f"{' '.join(args)} has no {bad}", rc == 0 and bad not in out, out)
    p = subprocess.run([server_bin, "--help"], capture_output=True, text=True, timeout=30)
    line = next((l for l in p.stdout.splitlines() if "--drain-timeout-ms" in l), "")
    check("beamcast-server --help describes --drain-timeout-ms", "SIGTERM" in p.stdout, line)

    # scripts/run.sh installs the run set only; the tests install both.
    deps = os.path.join(ROOT, "scripts", "install-deps.sh")
    run_set = subprocess.run(["bash", deps, "run", "--list"], capture_output=True, text=True).stdout.split()
    test_set = subprocess.run(["bash", deps, "test", "--list"], capture_output=True, text=True).stdout.split()
    dev = {"chromium", "clang-14", "clang-tidy-14", "haproxy", "python3-matplotlib", "libgtest-dev",
           "nodejs", "glslang-tools"}
    check("install-deps.sh run: no development or test packages",
          run_set and not dev & set(run_set), sorted(dev & set(run_set)))
    check("install-deps.sh test: the run set and the test packages",
          set(run_set) <= set(test_set) and dev <= set(test_set))
    with open(os.path.join(ROOT, "scripts", "run.sh")) as f:
        check("scripts/run.sh builds in run mode", "scripts/build.sh run" in f.read())
    return summary()


if __name__ == "__main__":
    sys.exit(main())
