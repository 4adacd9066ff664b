#!/usr/bin/env python3
"""The gallery: renders every scene in examples/ with `beamcast render` into
docs/img/gallery/ and writes docs/guide/gallery.md, a picture of each with the
command that made it.

Usage:
  scripts/gallery.py [--beamcast build/bin/beamcast] [--size 256] [--only NAME ...]
  scripts/gallery.py --http http://127.0.0.1:7879    # on a running server instead
  scripts/gallery.py --check     # every example has its picture and its entry (CI)

Frames are rendered at --size pixels on their longer side (the camera's aspect
kept) to keep the repository small; `beamcast render examples/NAME.json` gives
them at the scene's own size.
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
EXAMPLES = os.path.join(ROOT, "examples")
IMG = os.path.join(ROOT, "docs", "img", "gallery")
PAGE = os.path.join(ROOT, "docs", "guide", "gallery.md")


def examples():
    return sorted(f[:-5] for f in os.listdir(EXAMPLES)
                  if f.endswith(".json") and not f.startswith("."))


def cameras(name):
    """(camera name, width, height) of each camera of the scene (rigs give
    several frames: their names are read from the render's output instead)."""
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        scene = json.load(f)
    out = []
    for i, c in enumerate(scene.get("cameras", [])):
        out.append((c.get("name", f"camera_{i}"), c.get("width", 512), c.get("height", 512)))
    return out


def describe(name):
    """What the scene holds, in a few words, from its own keys."""
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        s = json.load(f)
    parts = []
    if s.get("beams"):
        parts.append(f"{len(s['beams'])} beam{'s' if len(s['beams']) != 1 else ''}")
    kinds = sorted({o.get("type", "?") for o in s.get("occluders", [])})
    if kinds:
        parts.append("occluders: " + ", ".join(kinds))
    if s.get("lights"):
        parts.append(f"{len(s['lights'])} light{'s' if len(s['lights']) != 1 else ''} (photon GI)")
    if s.get("medium") or s.get("media"):
        parts.append("fog")
    if s.get("volumes"):
        parts.append("volume")
    cams = s.get("cameras", [])
    if len(cams) > 1:
        parts.append(f"{len(cams)} cameras")
    return "; ".join(parts)


def size_arg(w, h, longest):
    scale = min(1.0, longest / max(w, h))
    return f"{max(8, round(w * scale))}x{max(8, round(h * scale))}"


def render(beamcast, name, longest):
    """Renders one example; returns [(png file name, command, seconds)]."""
    out = []
    cams = cameras(name)
    # One size for all of a scene's cameras: the first camera's, scaled.
    w, h = (cams[0][1], cams[0][2]) if cams else (512, 512)
    size = size_arg(w, h, longest)
    tmp = os.path.join(IMG, "." + name)
    os.makedirs(tmp, exist_ok=True)
    cmd = [beamcast, "render", os.path.join(EXAMPLES, name + ".json"), "--size", size, "--out", tmp]
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    seconds = time.monotonic() - t0
    shown = f"build/bin/beamcast render examples/{name}.json --size {size} --out /tmp/{name}"
    for f in sorted(os.listdir(tmp)):
        if not f.endswith(".png"):
            continue
        target = f"{name}_{f}" if not f.startswith(name + "_") else f
        os.replace(os.path.join(tmp, f), os.path.join(IMG, target))
        out.append((target, shown, seconds))
    for f in os.listdir(tmp):
        os.remove(os.path.join(tmp, f))
    os.rmdir(tmp)
    return out


def render_http(url, name, longest):
    """As render(), through a running server's POST /v1/render (the same
    renderer; the cameras resized as --size does)."""
    import base64
    import urllib.request
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        scene = json.load(f)
    cams = cameras(name)
    w, h = (cams[0][1], cams[0][2]) if cams else (512, 512)
    size = size_arg(w, h, longest)
    sw, sh = (int(v) for v in size.split("x"))
    resized = []
    for c in scene.get("cameras", []):
        c = dict(c)
        if "rig" not in c:
            c["width"], c["height"] = sw, sh
        resized.append(c)
    body = json.dumps({"scene": scene, "cameras": resized} if resized else {"scene": scene}).encode()
    req = urllib.request.Request(url.rstrip("/") + "/v1/render", data=body,
                                 headers={"Accept": "application/json"})
    t0 = time.monotonic()
    with urllib.request.urlopen(req, timeout=600) as r:
        result = json.load(r)
    seconds = time.monotonic() - t0
    shown = f"build/bin/beamcast render examples/{name}.json --size {size} --out /tmp/{name}"
    out = []
    for fr in result["frames"]:
        target = f"{name}_{fr['camera']}.png"
        with open(os.path.join(IMG, target), "wb") as f:
            f.write(base64.b64decode(fr["data_base64"]))
        out.append((target, shown, seconds))
    return out


def pictures(name):
    return sorted(f for f in os.listdir(IMG) if f.startswith(name + "_") and f.endswith(".png"))


def write_page(records, via_http):
    lines = [
        "# Gallery",
        "",
        "Every scene in `examples/`, rendered by `beamcast render` on the GPU path",
        "(here Mesa's llvmpipe), each with the command that made it. Generated by",
        "`scripts/gallery.py` (pictures in `docs/img/gallery/`, at most 256 pixels on",
        "a side; leave out `--size` for the scene's own size). `scripts/gallery.py",
        "--check` (the test `docs.gallery`) fails when an example has no picture here.",
        "",
    ]
    if via_http:
        lines += ["These pictures were rendered through a running server (`scripts/gallery.py",
                        "--http URL`, POST /v1/render with the cameras resized as `--size` does): the",
                        "same renderer and the same frames as the command shown.", ""]
    for name in examples():
        lines.append(f"## {name}")
        lines.append("")
        lines.append(f"[examples/{name}.json](../../examples/{name}.json): {describe(name)}.")
        lines.append("")
        rec = records.get(name)
        if rec:
            lines.append("    " + rec["command"])
            lines.append("")
        for p in pictures(name):
            lines.append(f"![{name}: {p[len(name) + 1:-4]}](../img/gallery/{p})")
        lines.append("")
    with open(PAGE, "w") as f:
        f.write("\n".join(lines).rstrip() + "\n")


def check():
    missing = []
    with open(PAGE) as f:
        page = f.read()
    for name in examples():
        if not pictures(name):
            missing.append(f"{name}: no picture in docs/img/gallery/")
        if f"## {name}\n" not in page:
            missing.append(f"{name}: no entry in docs/guide/gallery.md")
        for p in pictures(name):
            if f"../img/gallery/{p})" not in page:
                missing.append(f"{name}: {p} not on the page")
    for m in missing:
        print("gallery:", m, "(run scripts/gallery.py --only NAME)", file=sys.stderr)
    print(f"gallery: {len(examples())} examples, {len(missing)} problems")
    return 1 if missing else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--beamcast", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--size", type=int, default=256, help="pixels on the longer side")
    ap.add_argument("--only", action="append", help="render only these examples (repeatable)")
    ap.add_argument("--check", action="store_true", help="only check that every example is shown")
    ap.add_argument("--http", help="render on the beamcast-server at this HTTP URL (POST /v1/render) "
                                   "instead of running beamcast render")
    args = ap.parse_args()
    if args.check:
        return check()
    os.makedirs(IMG, exist_ok=True)
    # The commands of earlier runs are kept in a small index beside the pictures.
    index_file = os.path.join(IMG, "index.json")
    records = {}
    if os.path.exists(index_file):
        with open(index_file) as f:
            records = json.load(f)
    for name in args.only or examples():
        for p in pictures(name):
            os.remove(os.path.join(IMG, p))
        made = (render_http(args.http, name, args.size) if args.http
                else render(args.beamcast, name, args.size))
        records[name] = {"command": made[0][1] if made else "", "seconds": round(made[0][2], 1) if made else 0,
                         "pictures": [m[0] for m in made]}
        print(f"{name}: {len(made)} picture(s), {records[name]['seconds']} s", flush=True)
    with open(index_file, "w") as f:
        json.dump(records, f, indent=1, sort_keys=True)
        f.write("\n")
    write_page(records, bool(args.http))
    return check()


if __name__ == "__main__":
    sys.exit(main())
