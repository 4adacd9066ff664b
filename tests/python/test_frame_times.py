#!/usr/bin/env python3
"""bench/frame_times.py end to end at a tiny size, on a server it starts.

    python3 tests/python/test_frame_times.py build/bin/beamcast-server OUT_DIR

Checks what holds on any machine: every chosen scene gets a row without an
error; each row's passes are the ones its content calls for (the beam-only
scene runs no photon, medium or volume pass; the Cornell box runs the
photon passes and no beam pass; the volume scene runs `volumes`); GPU ms is
positive and no larger than render_ms plus rounding (render_ms contains the
GPU passes). Times are recorded, never asserted. Also parses
scripts/gpu_benches.sh (bash -n), which only a GPU machine runs whole.
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    server, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "bench", "frame_times.py"), "--out", out,
                    "--server", server, "--sizes", "32", "--frames", "1",
                    "--only", "beams", "gi", "volume_ml256"], check=True, timeout=240)
    with open(os.path.join(out, "frame_times.csv")) as f:
        rows = {r["scene"]: r for r in csv.DictReader(f)}
    failed = []

    def check(name, ok, detail):
        print(("PASS " if ok else "FAIL ") + name + ": " + detail, flush=True)
        if not ok:
            failed.append(name)

    check("every scene has a row", sorted(rows) == ["beams", "gi", "volume_ml256"], str(sorted(rows)))
    passes = {n: set(r["passes"].split()[0::2]) for n, r in rows.items()}
    for n, r in rows.items():
        check(f"{n}: no error", not r["error"], r["error"])
        gpu, render = float(r["gpu_ms"] or 0), float(r["render_ms"] or 0)
        # render_ms holds the GPU passes; 0.05 ms covers the two roundings to 0.01 ms.
        check(f"{n}: 0 < GPU ms <= render ms", 0 < gpu <= render + 0.05, f"gpu {gpu}, render {render}")
    photon = {"photons", "gi_resolve", "direct", "gbuffer", "volume_photons",
              "volume_grid"}
    check("beams: only beam passes", "beams" in passes.get("beams", set()) and
          not passes.get("beams", set()) & (photon | {"volumes"}), str(passes.get("beams")))
    check("gi: photon passes, no beam pass", {"photons", "gi_resolve"} <= passes.get("gi", set()) and
          "beams" not in passes.get("gi", set()), str(passes.get("gi")))
    check("volume: the volume pass alone", "volumes" in passes.get("volume_ml256", set()) and
          not passes.get("volume_ml256", set()) & photon, str(passes.get("volume_ml256")))
    syntax = subprocess.run(["bash", "-n", os.path.join(ROOT, "scripts", "gpu_benches.sh")],
                            capture_output=True, text=True)
    check("scripts/gpu_benches.sh parses", syntax.returncode == 0, syntax.stderr.strip())
    if failed:
        print(f"{len(failed)} check(s) failed: {failed}")
        sys.exit(1)


if __name__ == "__main__":
    main()
