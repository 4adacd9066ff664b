#!/usr/bin/env python3
"""Writes the seed corpus of the fuzz targets (fuzz/corpus/<target>/): valid
messages built from examples/ plus hand-made broken ones. Re-run after a
protocol change; libFuzzer mutates from these."""
import json
import pathlib
import struct

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "fuzz" / "corpus"


def frame(js: bytes, binary: bytes = b"") -> bytes:
    return b"BCP1" + struct.pack(">II", len(js), len(binary)) + js + binary


def write(target: str, name: str, data: bytes) -> None:
    d = OUT / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)


def compact(obj) -> bytes:
    return json.dumps(obj, separators=(",", ":")).encode()


scenes = {p.stem: json.loads(p.read_text()) for p in sorted((ROOT / "examples").glob("*.json"))}
small = scenes["paper_1set"]
small_cam = dict(small["cameras"][0], width=16, height=16)
small = dict(small, cameras=[small_cam])

# fuzz_framing: byte 0 picks the body limit (index 5: 1 MiB), byte 1 the chunk size.
ping = compact({"id": 1, "method": "ping", "params": {"x": 1}})
write("fuzz_framing", "one_frame", b"\x05\x00" + frame(ping))
write("fuzz_framing", "two_frames_binary", b"\x05\x07" + frame(ping) + frame(b'{"id":2}', b"\x89PNG\r\n"))
write("fuzz_framing", "bad_magic", b"\x05\x03" + b"HTTP" + frame(ping)[4:])
write("fuzz_framing", "empty_json", b"\x05\x01" + frame(b""))
write("fuzz_framing", "too_large", b"\x02\x05" + frame(ping))
write("fuzz_framing", "truncated", b"\x05\x02" + frame(ping)[:20])
write("fuzz_framing", "huge_length", b"\x05\x0b" + b"BCP1\xff\xff\xff\xff\xff\xff\xff\xff")

# fuzz_request: whole requests, valid and broken.
reqs = {
    "hello": {"id": 1, "method": "hello", "params": {"protocol": 1}},
    "hello_token": {"id": 1, "method": "hello", "params": {"protocol": 1, "token": "s3cret"}},
    "ping": {"id": "p", "method": "ping", "params": {"a": [1, 2, {"b": None}]}},
    "stats": {"id": 3, "method": "stats"},
    "stats_prom": {"id": 3, "method": "stats", "params": {"format": "prometheus"}},
    "render_inline": {"id": 4, "method": "render", "params": {"scene": small}},
    "render_cameras": {"id": 5, "method": "render", "params": {
        "scene_id": "demo", "cameras": [small_cam, dict(small_cam, rotation=[1, 0, 0, 0])],
        "output": {"exposure": 2.0, "tone": "reinhard", "bit_depth": 16}, "encoding": "base64"}},
    "scene_put": {"id": 6, "method": "scene.put", "params": {"scene_id": "s.1", "scene": small}},
    "scene_update": {"id": 7, "method": "scene.update", "params": {
        "scene_id": "s.1", "patch": {"output": {"exposure": 0.5}, "background": [0.1, 0, 0]}}},
    "scene_delete": {"id": 8, "method": "scene.delete", "params": {"scene_id": "s.1"}},
    "unknown_method": {"id": 9, "method": "explode"},
    "bad_id": {"id": [1], "method": "ping"},
    "extra_field": {"id": 1, "method": "ping", "junk": True},
    "bad_scene": {"id": 4, "method": "render", "params": {"scene": {"beams": [{"type": "sphere", "radius": -1}]}}},
    "both_scene_and_id": {"id": 4, "method": "render", "params": {"scene": {}, "scene_id": "x"}},
    "mesh_escape": {"id": 4, "method": "render", "params": {"scene": dict(small, occluders=[
        {"type": "mesh", "file": "../../etc/passwd"}])}},
    "long_utf8_string": {"id": 4, "method": "render", "params": {"scene": dict(small, beams=[
        dict(small["beams"][0], density="\u00e9" * 40)])}},
}
for name, r in reqs.items():
    write("fuzz_request", name, compact(r))
write("fuzz_request", "not_json", b'{"id":1,"method":')
write("fuzz_request", "huge_number", b'{"id":1,"method":"render","params":{"scene":{"beams":[],"background":[1e999,0,0]}}}')
write("fuzz_request", "not_object", b"[1,2,3]")

# fuzz_scene: every example scene plus broken ones.
for name, s in scenes.items():
    write("fuzz_scene", name, json.dumps(s).encode())
write("fuzz_scene", "camera_only", compact(small_cam))
write("fuzz_scene", "output_only", compact({"exposure": 1.5, "tone": "clamp", "bit_depth": 8}))
write("fuzz_scene", "nan_radius", b'{"beams":[{"type":"sphere","center":[0,0,0],"radius":NaN}]}')
write("fuzz_scene", "table_density", compact(dict(small, beams=[dict(small["beams"][0], density={
    "type": "table", "values": [1.0, 0.8, 0.5, 0.2, 0.0]})])))
write("fuzz_scene", "occluders", compact(dict(small, occluders=[
    {"type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0]},
    {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1]},
    {"type": "sphere", "center": [0, 0, 0], "radius": 0.5},
    {"type": "mesh", "file": "meshes/torus.obj", "scale": [1, 2, 1]}])))
write("fuzz_scene", "procedural_volumes", compact({
    "volumes": [
        {"source": {"type": "marschner_lobb", "resolution": 9}, "transfer": {"preset": "ml"}},
        {"source": {"type": "heat", "resolution": 5}, "spacing": 0.25, "rotation": [1, 0, 0, 1],
         "range": [0.1, 0.9], "transfer": {"points": [[0, 0, 0, 0, 0], [0.5, 1, 0.5, 0.2, 0.3],
                                                      [1, 1, 1, 1, 0.9]], "opacity_unit": 0.05},
         "intensity": 2}],
    "volume": {"samples_per_voxel": 1, "level": 1, "pyramid": "max"},
    "cameras": [dict(scenes["volume_ml"]["cameras"][0], width=16, height=16)]}))

# fuzz_obj: byte 0 picks transform and limits.
torus = (ROOT / "examples" / "meshes" / "torus.obj").read_bytes()
write("fuzz_obj", "torus", b"\x00" + torus)
write("fuzz_obj", "torus_limited", b"\x18" + torus)
write("fuzz_obj", "quad", b"\x07v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
write("fuzz_obj", "negative_index", b"\x00v 0 0 0\nv 1 0 0\nv 1 1 0\nf -1 -2 -3\n")
write("fuzz_obj", "index_out_of_range", b"\x00v 0 0 0\nv 1 0 0\nf 1 2 9\n")
write("fuzz_obj", "nan_vertex", b"\x00v nan 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
write("fuzz_obj", "huge_vertex", b"\x02v 1e300 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
write("fuzz_obj", "texcoords_normals", b"\x00v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3//1\nmtllib x.mtl\nusemtl m\n")
write("fuzz_obj", "no_faces", b"\x00v 0 0 0\n# nothing\n")
