#!/usr/bin/env python3
"""Structure-aware hostile inputs for fuzz_request and fuzz_scene (issue 19):
deep nesting, huge arrays, long strings and keys, extreme numbers, in every
place a request can hold JSON (params, inline scene, scene.update's patch,
the id). Small random-looking inputs never reach these shapes: the remote
crash of issue 19 needed 60 000 nested objects.

    python3 fuzz/make_hostile_corpus.py OUTDIR [MAX_BYTES]

Writes OUTDIR/fuzz_request/* and OUTDIR/fuzz_scene/*, each at most MAX_BYTES
(default 65536, the ctest fuzz runs' -max_len). Deterministic (seeded), so a
CI run replays the same inputs; generated at test time, not committed.
"""
import json
import pathlib
import random
import sys

OUT = pathlib.Path(sys.argv[1])
MAX = int(sys.argv[2]) if len(sys.argv) > 2 else 65536
rng = random.Random(19)

BASE_SCENE = {
    "beams": [{"type": "capsule", "p0": [0, 0, 0], "p1": [0, 1, 0], "radius": 0.2,
               "density": "abe"}],
    "cameras": [{"position": [0, 0.5, 3], "target": [0, 0.5, 0], "width": 8, "height": 8}],
}

count = {"fuzz_request": 0, "fuzz_scene": 0}


def write(target, name, text):
    data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    if len(data) > MAX:
        return
    d = OUT / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)
    count[target] += 1


def deep(kind, levels, leaf="1"):
    if kind == "obj":
        return '{"a":' * levels + leaf + "}" * levels
    if kind == "arr":
        return "[" * levels + leaf + "]" * levels
    # alternating objects and arrays
    opens = "".join('{"k":[' for _ in range(levels // 2))
    return opens + leaf + "]}" * (levels // 2)


def request(method, params_text, rid='"h"', tail=""):
    return '{"id":' + rid + ',"method":"' + method + '","params":' + params_text + tail + "}"


def scene_with(field_text):
    s = json.dumps(BASE_SCENE)
    return s[:-1] + ',"extra":' + field_text + "}"


# 1. Deep nesting around the limit (64) and far past it, in every place.
depths = [62, 63, 64, 65, 66, 100, 1000, 10000, 21000]
for kind in ("obj", "arr", "mix"):
    for d in depths:
        write("fuzz_request", f"deep_ping_{kind}_{d}", request("ping", '{"x":' + deep(kind, d) + "}"))
        write("fuzz_request", f"deep_patch_{kind}_{d}",
              request("scene.update", '{"scene_id":"s","patch":{"beams":[{"density":' + deep(kind, d) + "}]}}"))
        write("fuzz_request", f"deep_scene_{kind}_{d}",
              request("render", '{"scene":' + scene_with(deep(kind, d)) + "}"))
        write("fuzz_request", f"deep_before_id_{kind}_{d}",
              '{"params":{"x":' + deep(kind, d) + '},"method":"ping","id":"late"}')
        write("fuzz_scene", f"deep_{kind}_{d}", scene_with(deep(kind, d)))
        write("fuzz_scene", f"deep_camera_{kind}_{d}",
              '{"position":[0,0,3],"target":[0,0,0],"name":' + deep(kind, d, '"n"') + "}")
# unbalanced: deep and never closed
write("fuzz_request", "deep_unclosed", request("ping", "[" * 30000))

# 2. Huge arrays and objects (many values, shallow).
for n in (5000, 20000):
    write("fuzz_request", f"wide_array_{n}", request("ping", '{"x":[' + ",".join(["0"] * n) + "]}"))
    write("fuzz_request", f"wide_object_{n}",
          request("ping", "{" + ",".join(f'"k{i}":{i}' for i in range(n // 4)) + "}"))
    beams = [dict(BASE_SCENE["beams"][0], p0=[i, 0, 0], p1=[i, 1, 0]) for i in range(n // 60)]
    write("fuzz_request", f"many_beams_{n}",
          request("render", json.dumps({"scene": dict(BASE_SCENE, beams=beams)})))
    write("fuzz_request", f"many_cameras_{n}",
          request("render", json.dumps({"scene": BASE_SCENE,
                                        "cameras": [{"width": 4, "height": 4}] * (n // 30)})))
    write("fuzz_scene", f"many_beams_{n}", json.dumps(dict(BASE_SCENE, beams=beams)))
    write("fuzz_request", f"repeated_keys_{n}",
          request("ping", "{" + ",".join(['"same":1'] * (n // 2)) + "}"))

# 3. Long strings: ids, keys, methods, scene ids, names, invalid UTF-8 inside.
for n in (129, 4096, 60000):
    long = "x" * n
    write("fuzz_request", f"long_id_{n}", request("ping", "{}", rid='"' + long + '"'))
    write("fuzz_request", f"long_key_{n}", request("ping", '{"' + long + '":1}'))
    write("fuzz_request", f"long_method_{n}", '{"id":1,"method":"' + long + '"}')
    write("fuzz_request", f"long_scene_id_{n}", request("scene.delete", '{"scene_id":"' + long + '"}'))
    write("fuzz_request", f"long_unknown_top_key_{n}", '{"id":1,"method":"ping","' + long + '":0}')
    write("fuzz_request", f"long_camera_name_{n}",
          request("render", json.dumps({"scene": BASE_SCENE, "cameras": [{"name": long}]})))
    write("fuzz_scene", f"long_key_{n}", scene_with('{"' + long + '":1}'))
write("fuzz_request", "id_multibyte_128", request("ping", "{}", rid='"' + "\u00e9" * 128 + '"'))
write("fuzz_request", "id_multibyte_129", request("ping", "{}", rid='"' + "\u00e9" * 129 + '"'))
write("fuzz_request", "id_invalid_utf8", b'{"id":"\xff\xfe","method":"ping"}')
write("fuzz_request", "escaped_surrogates", request("ping", '{"s":"\\ud800\\udc00\\ud800"}'))

# 4. Extreme numbers, in ids, sizes, coordinates and counts.
numbers = ["1e999", "-1e999", "1e308", "-1e308", "5e-324", "1e-400", "0e99999", "-0",
           "18446744073709551615", "18446744073709551616", "-9223372036854775808",
           "-9223372036854775809", "9" * 400, "1." + "0" * 400, "7.0", "7.5", "1E+2", "0.1e1"]
for i, num in enumerate(numbers):
    write("fuzz_request", f"num_id_{i}", request("ping", "{}", rid=num))
    write("fuzz_request", f"num_width_{i}",
          request("render", '{"scene":' + json.dumps(BASE_SCENE) + ',"cameras":[{"width":' + num + "}]}"))
    write("fuzz_request", f"num_cubemap_{i}",
          request("render", '{"scene":' + json.dumps(BASE_SCENE) +
                  ',"cameras":[{"rig":"cubemap","size":' + num + "}]}"))
    write("fuzz_request", f"num_radius_{i}",
          request("render", '{"scene":' + json.dumps(BASE_SCENE).replace('"radius": 0.2', '"radius": ' + num) + "}"))
    write("fuzz_request", f"num_protocol_{i}", request("hello", '{"protocol":' + num + "}"))
    write("fuzz_request", f"num_orbit_{i}",
          request("render", '{"scene":' + json.dumps(BASE_SCENE) +
                  ',"cameras":[{"rig":"orbit","count":' + num + "}]}"))
    write("fuzz_scene", f"num_coord_{i}",
          json.dumps(BASE_SCENE).replace('"p0": [0, 0, 0]', '"p0": [' + num + ", 0, 0]"))
# the id after several overflowing numbers
write("fuzz_request", "overflow_then_id",
      '{"params":{"a":[' + ",".join(["1e999"] * 20) + ']},"method":"ping","id":"z"}')

# 5. Random mixtures of the above shapes (seeded).
for i in range(60):
    parts = []
    for _ in range(rng.randint(1, 6)):
        pick = rng.randrange(4)
        if pick == 0:
            parts.append(deep(rng.choice(["obj", "arr", "mix"]), rng.choice([60, 64, 65, 70, 500])))
        elif pick == 1:
            parts.append("[" + ",".join(rng.choice(numbers) for _ in range(rng.randint(1, 50))) + "]")
        elif pick == 2:
            parts.append('"' + "y" * rng.randint(1, 3000) + '"')
        else:
            parts.append(json.dumps(BASE_SCENE))
    body = "{" + ",".join(f'"p{j}":{p}' for j, p in enumerate(parts)) + "}"
    write("fuzz_request", f"mix_{i}", request(rng.choice(["ping", "render", "scene.put", "hello"]), body))

print(f"make_hostile_corpus: {count['fuzz_request']} fuzz_request and "
      f"{count['fuzz_scene']} fuzz_scene inputs in {OUT}")
