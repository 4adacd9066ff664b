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


def quat_from_axes(x, y, z):
    """[w, x, y, z] of the rotation whose matrix has columns x, y, z
    (protocol/slim_model.cpp, same pivots)."""
    m00, m11, m22 = x[0], y[1], z[2]
    trace = m00 + m11 + m22
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = [0.25 * s, (y[2] - z[1]) / s, (z[0] - x[2]) / s, (x[1] - y[0]) / s]
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = [(y[2] - z[1]) / s, 0.25 * s, (y[0] + x[1]) / s, (z[0] + x[2]) / s]
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = [(z[0] - x[2]) / s, (y[0] + x[1]) / s, 0.25 * s, (z[1] + y[2]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = [(x[1] - y[0]) / s, (z[0] + x[2]) / s, (z[1] + y[2]) / s, 0.25 * s]
    n = math.sqrt(sum(c * c for c in q))
    return [c / n for c in q]


def slim_torus(major, minor, nu, nv, support=1.5):
    """A SLIM torus (axis y) of support spheres, each holding the torus's
    second-order expansion at its centre (tests/common/slim_shapes.hpp's
    slim_torus, the same surface): no mesh and no fit needed."""
    spheres = []
    spacing = max(2.0 * math.pi * (major + minor) / nu, 2.0 * math.pi * minor / nv)
    for i in range(nu):
        theta = 2.0 * math.pi * (i + 0.5) / nu
        for j in range(nv):
            phi = 2.0 * math.pi * (j + 0.5) / nv
            radial = [math.cos(theta), 0.0, math.sin(theta)]
            n = [math.cos(phi) * radial[0], math.sin(phi), math.cos(phi) * radial[2]]
            ring_r = major + minor * math.cos(phi)
            p = [ring_r * radial[0], minor * math.sin(phi), ring_r * radial[2]]
            ring = [-math.sin(theta), 0.0, math.cos(theta)]
            tube = cross(n, ring)
            k_ring = math.cos(phi) / ring_r
            spheres.append({
                "center": [round(c, 5) for c in p],
                "radius": round(support * spacing, 5),
                "rotation": [round(c, 6) for c in quat_from_axes(ring, tube, n)],
                "coefficients": [round(-0.5 * k_ring, 6), 0, round(-0.5 / minor, 6), 0, 0, 0]})
    return spheres


def write_compact_list(name, scene, key_path):
    """As write(), with the list at key_path one element per line (a SLIM
    model's spheres would take 30 lines each with indent=2)."""
    marker = "@@LIST@@"
    parent = scene
    for k in key_path[:-1]:
        parent = parent[k]
    items = parent[key_path[-1]]
    parent[key_path[-1]] = marker
    text = json.dumps(scene, indent=2)
    parent[key_path[-1]] = items
    lines = ",\n".join("  " + json.dumps(it, separators=(",", ":")) for it in items)
    with open(os.path.join(OUT, name), "w") as f:
        f.write(text.replace(json.dumps(marker), "[\n" + lines + "\n]"))
        f.write("\n")


def write(name, scene):
    with open(os.path.join(OUT, name), "w") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")


# The Cornell box as measured (https://www.graphics.cornell.edu/online/box/data.html):
# millimetres, each surface a quadrilateral listed by its four vertices.
CORNELL_WHITE = (0.725, 0.71, 0.68)
CORNELL_RED = (0.63, 0.065, 0.05)
CORNELL_GREEN = (0.14, 0.45, 0.091)
CORNELL_ROOM = {
    "floor": [(552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2)],
    "ceiling": [(556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0)],
    "back": [(549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2)],
    "green": [(0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2)],
    "red": [(552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0)],
}
CORNELL_SHORT = [
    [(130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)],
    [(290.0, 0.0, 114.0), (290.0, 165.0, 114.0), (240.0, 165.0, 272.0), (240.0, 0.0, 272.0)],
    [(130.0, 0.0, 65.0), (130.0, 165.0, 65.0), (290.0, 165.0, 114.0), (290.0, 0.0, 114.0)],
    [(82.0, 0.0, 225.0), (82.0, 165.0, 225.0), (130.0, 165.0, 65.0), (130.0, 0.0, 65.0)],
    [(240.0, 0.0, 272.0), (240.0, 165.0, 272.0), (82.0, 165.0, 225.0), (82.0, 0.0, 225.0)],
]
CORNELL_TALL = [
    [(423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)],
    [(423.0, 0.0, 247.0), (423.0, 330.0, 247.0), (472.0, 330.0, 406.0), (472.0, 0.0, 406.0)],
    [(472.0, 0.0, 406.0), (472.0, 330.0, 406.0), (314.0, 330.0, 456.0), (314.0, 0.0, 456.0)],
    [(314.0, 0.0, 456.0), (314.0, 330.0, 456.0), (265.0, 330.0, 296.0), (265.0, 0.0, 296.0)],
    [(265.0, 0.0, 296.0), (265.0, 330.0, 296.0), (423.0, 330.0, 247.0), (423.0, 0.0, 247.0)],
]


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def fit_quad(v, toward):
    """The parallelogram closest to a measured quadrilateral v0..v3: centred on the
    vertices' mean, edges the means of opposite sides (each vertex moves by a
    quarter of v0 - v1 + v2 - v3, at most 1.6 mm here), one-sided with its normal
    cross(edge_u, edge_v) pointing to `toward`."""
    eu = [((v[1][k] - v[0][k]) + (v[2][k] - v[3][k])) / 2 for k in range(3)]
    ev = [((v[3][k] - v[0][k]) + (v[2][k] - v[1][k])) / 2 for k in range(3)]
    c = [sum(p[k] for p in v) / 4 for k in range(3)]
    n = cross(eu, ev)
    if sum(n[k] * (toward[k] - c[k]) for k in range(3)) < 0:
        eu, ev = ev, eu
    corner = [round(c[k] - eu[k] / 2 - ev[k] / 2, 4) for k in range(3)]
    return {"type": "quad", "corner": corner, "edge_u": [round(x, 4) for x in eu],
            "edge_v": [round(x, 4) for x in ev], "sides": 1}


def outward(v, centre):
    """A point beyond face v as seen from the block's centre (the normal's target)."""
    c = [sum(p[k] for p in v) / 4 for k in range(3)]
    return [2 * c[k] - centre[k] for k in range(3)]


def cornell_room():
    inside = (278.0, 274.4, 279.6)
    colours = {"red": CORNELL_RED, "green": CORNELL_GREEN}
    walls = []
    for name, v in CORNELL_ROOM.items():
        q = fit_quad(v, inside)
        q["albedo"] = list(colours.get(name, CORNELL_WHITE))
        walls.append(q)
    return walls


def cornell_block(faces):
    pts = [p for f in faces for p in f]
    centre = [sum(p[k] for p in pts) / len(pts) for k in range(3)]
    out = []
    for f in faces:
        q = fit_quad(f, outward(f, centre))
        q["albedo"] = list(CORNELL_WHITE)
        out.append(q)
    return out


def cornell(occluders):
    # Light 130 x 105 mm just below the ceiling, facing down; camera: 35 mm
    # focal length on a 25 mm film, fov_y = 2 atan(12.5 / 35) = 39.3077 deg.
    return {
        "background": [0.0, 0.0, 0.0],
        "lights": [{"type": "quad", "corner": [213.0, 548.7, 227.0], "edge_u": [130.0, 0.0, 0.0],
                    "edge_v": [0.0, 0.0, 105.0], "radiance": [17.0, 12.0, 4.0]}],
        "occluders": cornell_room() + occluders,
        "cameras": [camera("view", [278.0, 273.0, -800.0], [278.0, 273.0, 0.0],
                           fov_y=round(2 * math.degrees(math.atan(12.5 / 35.0)), 4),
                           near=1.0, far=3000.0)],
        "output": {"exposure": 2.0},
    }


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
    write("cornell_box.json", cornell(cornell_block(CORNELL_SHORT) + cornell_block(CORNELL_TALL)))
    write("cornell_caustic.json", cornell([
        {"type": "sphere", "center": [380.0, 100.0, 380.0], "radius": 100.0,
         "material": {"type": "mirror", "reflectance": [0.95, 0.95, 0.95]}},
        {"type": "sphere", "center": [175.0, 100.0, 200.0], "radius": 100.0,
         "material": {"type": "glass", "ior": 1.5}},
    ]))
    # The room alone, lit only by two glowing beams (issue 14: beams that emit).
    room = cornell(cornell_block(CORNELL_SHORT))
    del room["lights"]
    write("beam_lit_room.json", dict(
        room,
        beams=[
            {"type": "capsule", "p0": [300.0, 90.0, 330.0], "p1": [300.0, 430.0, 330.0],
             "radius": 28.0, "color": [1.0, 0.55, 0.2], "intensity": 1.5, "density": "quadratic",
             "emit": True},
            {"type": "sphere", "center": [130.0, 380.0, 230.0], "radius": 50.0,
             "color": [0.3, 0.55, 1.0], "intensity": 3.0,
             "density": {"type": "gaussian", "sigma": 0.4}, "emit": True},
        ]))
    # Seed 001's stage in fog (its fig 6.3: a spot light in a homogeneous
    # medium, 50 000 photons at 512x512): a floor, a back wall and two side
    # walls open to the camera, a sphere and a box, the spot from above.
    wall = [0.75, 0.75, 0.75]
    stage = {
        "lights": [{"type": "spot", "position": [0.0, 5.5, 1.0], "direction": [0.0, -5.5, -1.0],
                    "inner_deg": 15.0, "outer_deg": 25.0, "power": 600.0}],
        "occluders": [
            {"type": "quad", "corner": [-5, 0, 5], "edge_u": [10, 0, 0], "edge_v": [0, 0, -10],
             "albedo": wall},
            {"type": "quad", "corner": [-5, 0, -5], "edge_u": [10, 0, 0], "edge_v": [0, 6, 0],
             "albedo": wall},
            {"type": "quad", "corner": [-5, 0, 5], "edge_u": [0, 0, -10], "edge_v": [0, 6, 0],
             "albedo": [0.7, 0.3, 0.25]},
            {"type": "quad", "corner": [5, 0, -5], "edge_u": [0, 0, 10], "edge_v": [0, 6, 0],
             "albedo": [0.3, 0.45, 0.7]},
            {"type": "sphere", "center": [-1.2, 0.8, -0.5], "radius": 0.8, "albedo": [0.8, 0.7, 0.3]},
            {"type": "box", "center": [1.5, 0.6, -1.0], "size": [1.2, 1.2, 1.2],
             "rotation": [0.9238795, 0.0, 0.3826834, 0.0], "albedo": [0.6, 0.6, 0.65]},
        ],
        "medium": {"sigma_s": 0.05, "sigma_a": 0.01, "g": 0.3},
        "gi": {"photons": 50000},
        "cameras": [camera("view", [0.0, 2.2, 9.0], [0.0, 1.5, 0.0], fov_y=45)],
        "output": {"exposure": 0.8},
    }
    write("fog_stage.json", stage)
    # Its fig 5.9: heterogeneous fog, a dense layer near the floor (a box
    # region of medium) under the thin fog of the stage.
    # Glowing beams that light the fog around them (issue 15, item 4): the
    # stage without its spot, an emitting capsule and sphere in the fog.
    glow = dict(stage, beams=[
        {"type": "capsule", "p0": [0.6, 0.3, 0.8], "p1": [0.6, 3.6, 0.8], "radius": 0.25,
         "color": [1.0, 0.55, 0.2], "intensity": 12.0, "density": "quadratic", "emit": True},
        {"type": "sphere", "center": [-2.2, 2.6, -1.0], "radius": 0.5, "color": [0.3, 0.55, 1.0],
         "intensity": 15.0, "density": {"type": "gaussian", "sigma": 0.4}, "emit": True}])
    del glow["lights"]
    write("beam_fog.json", glow)
    write("ground_fog.json", dict(stage, media=[
        {"type": "box", "min": [-5.0, 0.0, -5.0], "max": [5.0, 0.8, 5.0],
         "sigma_s": 0.6, "sigma_a": 0.05, "g": 0.3}]))
    # A SLIM surface that needs no model file (issue 40, item 5): a torus of
    # 384 support spheres written inline, a beam through its hole.
    write_compact_list("slim_torus.json", {
        "background": [0.02, 0.02, 0.03],
        "light": {"direction": [-0.4, -1.0, -0.5], "intensity": 1.0, "ambient": 0.2},
        "beams": [{"type": "capsule", "p0": [0.0, -1.8, 0.0], "p1": [0.0, 1.8, 0.0], "radius": 0.3,
                   "color": [0.35, 0.6, 1.0], "intensity": 1.5, "density": "quadratic"}],
        "occluders": [{"type": "slim", "material": {"type": "diffuse", "albedo": [0.8, 0.55, 0.3]},
                       "spheres": slim_torus(1.2, 0.45, 32, 12)}],
        "cameras": [camera("view", [0.0, 2.6, 4.2], [0.0, 0.0, 0.0], 256, 256, fov_y=45)],
    }, ["occluders", 0, "spheres"])


if __name__ == "__main__":
    main()
