#!/usr/bin/env python3
"""Writes the example scenes in examples/ (deterministic; rerun after format changes).

The paper's "set" is a sphere at a point plus a half-capsule (cylinder and end
hemisphere) leaving it; sets 1, 5 and 10 at 512x512 reproduce its benchmark.
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "examples")


def paper_sets(n):
    beams = []
    for i in range(n):
        a = 2.0 * math.pi * i / max(n, 1)
        # Sets on a ring, each beam leaving its sphere outwards and slightly up.
        c = [1.6 * math.cos(a) if n > 1 else 0.0, 0.0, 1.6 * math.sin(a) if n > 1 else 0.0]
        d = [math.cos(a + 0.6), 0.35, math.sin(a + 0.6)]
        norm = math.sqrt(sum(x * x for x in d))
        tip = [c[k] + 2.2 * d[k] / norm for k in range(3)]
        hue = i / max(n, 1)
        color = [0.6 + 0.4 * math.cos(2 * math.pi * (hue + k / 3.0)) for k in range(3)]
        beams.append({"type": "sphere", "center": c, "radius": 0.55, "color": color,
                      "intensity": 1.0, "density": "abe"})
        beams.append({"type": "capsule", "p0": c, "p1": tip, "caps": [False, True],
                      "radius": 0.28, "color": color, "intensity": 1.0, "density": "abe"})
    return beams


def camera(name, pos, target, w=512, h=512, **extra):
    cam = {"name": name, "position": pos, "target": target, "width": w, "height": h}
    cam.update(extra)
    return cam


def write(name, scene):
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")


def main():
    for n in (1, 5, 10):
        write(f"paper_{n}set{'s' if n > 1 else ''}.json", {
            "background": [0.0, 0.0, 0.0],
            "beams": paper_sets(n),
            "cameras": [camera("view", [0.0, 3.5, 7.5], [0.0, 0.3, 0.0], fov_y=50)],
            "output": {"exposure": 0.6},
        })
    write("thin_shell.json", {
        "beams": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0,
                   "color": [0.4, 0.8, 1.0], "intensity": 1.0, "density": "shell"}],
        "cameras": [camera("view", [0.0, 0.0, 3.2], [0, 0, 0], fov_y=45)],
        "output": {"exposure": 0.5},
    })
    write("beam_occluder.json", {
        "background": [0.01, 0.01, 0.02],
        "light": {"direction": [-0.5, -1.0, -0.4], "intensity": 1.0, "ambient": 0.2},
        "beams": [
            {"type": "capsule", "p0": [-2.5, 0.6, 0.0], "p1": [2.5, 0.6, 0.0], "radius": 0.35,
             "color": [1.0, 0.5, 0.15], "intensity": 1.5, "density": "quadratic"},
            {"type": "sphere", "center": [0.0, 0.6, 0.0], "radius": 0.8,
             "color": [0.3, 0.5, 1.0], "density": {"type": "gaussian", "sigma": 0.35}},
        ],
        "occluders": [
            {"type": "plane", "point": [0, -0.5, 0], "normal": [0, 1, 0], "albedo": [0.6, 0.6, 0.6]},
            # The box stands inside the capsule: the beam ends on its faces.
            {"type": "box", "center": [1.4, 0.4, 0.0], "size": [0.3, 1.8, 1.0],
             "rotation": [0.9659258, 0.0, 0.258819, 0.0], "albedo": [0.8, 0.3, 0.25]},
            {"type": "sphere", "center": [-1.3, 0.2, 0.5], "radius": 0.45, "albedo": [0.3, 0.7, 0.35]},
        ],
        "cameras": [camera("view", [0.8, 2.0, 5.5], [0.0, 0.3, 0.0], fov_y=50)],
    })
    write("camera_inside.json", {
        "beams": [
            {"type": "capsule", "p0": [0, 0, -6], "p1": [0, 0, 6], "radius": 1.5,
             "color": [0.5, 1.0, 0.6], "intensity": 0.5, "density": "linear"},
            {"type": "sphere", "center": [0.4, 0.2, -3.0], "radius": 0.5,
             "color": [1.0, 0.4, 0.3], "density": "quadratic"},
        ],
        # Inside the capsule, looking along its axis and slightly off it.
        "cameras": [camera("along_axis", [0.3, 0.2, 4.0], [0.0, 0.0, -6.0], fov_y=70),
                    camera("across", [0.0, 0.5, 0.0], [3.0, 0.5, 0.3], fov_y=70)],
        "output": {"exposure": 0.35},
    })
    write("mesh_occluder.json", {
        "background": [0.02, 0.02, 0.03],
        "beams": [
            {"type": "capsule", "p0": [0, -1.2, 0], "p1": [0, 1.6, 0], "radius": 0.3,
             "color": [1.0, 0.8, 0.3], "intensity": 1.0, "density": "abe"},
        ],
        "occluders": [
            {"type": "mesh", "file": "meshes/torus.obj", "translate": [0, 0.2, 0], "scale": 0.9,
             "rotation": [0.9238795, 0.3826834, 0.0, 0.0], "albedo": [0.7, 0.7, 0.75]},
        ],
        "cameras": [camera("view", [0.0, 1.5, 4.0], [0.0, 0.2, 0.0], fov_y=50)],
        "output": {"exposure": 0.6},
    })
    write("multi_camera.json", {
        "beams": paper_sets(5)[:6] + [
            {"type": "sphere", "center": [0, 2.5, 0], "radius": 0.7, "color": [0.9, 0.9, 1.0],
             "density": "shell"}],
        "occluders": [{"type": "plane", "point": [0, -0.6, 0], "normal": [0, 1, 0]}],
        "cameras": [
            camera("front", [0.0, 1.5, 7.0], [0, 0.8, 0], 320, 240, fov_y=55),
            camera("top", [0.0, 9.0, 0.01], [0, 0, 0], 256, 256, fov_y=40),
            camera("ortho_side", [8.0, 1.0, 0.0], [0, 1.0, 0], 320, 240,
                   projection="orthographic", ortho_height=6.0),
            camera("wide", [3.0, 0.5, 3.0], [0, 0.8, 0], 384, 216, fov_y=100),
        ],
        "output": {"exposure": 0.7, "bit_depth": 16},
    })


if __name__ == "__main__":
    main()
