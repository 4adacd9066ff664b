#!/usr/bin/python3
"""Volume ray casting side by side with VTK 9.1's GPU ray cast mapper (issue 17,
item 6): time per frame and error against the same CPU reference, in one run.
/usr/bin/python3 bench/vtk_volume_bench.py --out DIR [--size N] [--quick]

The peer is Debian's python3-vtk9 (vtkOpenGLGPUVolumeRayCastMapper), run
under xvfb-run on Mesa's llvmpipe, the rasterizer Beamcast's EGL context gets
here; this script installs it (apt-get install -y python3-vtk9 xvfb xauth,
as root) when it is missing, never the test command. The VTK renders run in
a worker process (this file with --vtk-worker) under xvfb-run.

Same data: the volumes are written once as 16-bit raw files that both tools
read: Marschner-Lobb 41^3, computed here exactly as protocol/volume.cpp's
procedural_grid does (voxel i at -1 + 2i/(n-1), range [0, 1], rounded to 16
bits), and the skull (skull_2.9.inr from libcgal-demo, 64^3 float; fetched by
scripts/fetch_cgal_volumes.sh, skipped with a note if that fails), quantized
as Beamcast quantizes float data (its own min and max mapped to 0 and 65535).
A check renders the procedural (or INR) source and the raw file with the GPU
at a small size: the frames must agree bit for bit.

Same setup: the camera (position, target, up, vertical fov = VTK's
ViewAngle, near 0.01 and far 1000 = VTK's clipping range, image size), a
black background, the volume's origin and spacing (vtkImageData's), the
Beamcast range [0, 65535] so a stored value q means q / 65535 and VTK's
transfer function points sit at value x 65535 in data units (VTK's colour and
opacity tables span the functions' own range: the NATIVE range type),
trilinear interpolation, shading off, the transfer function (colours to a
vtkColorTransferFunction, opacities to a vtkPiecewiseFunction) with
opacity_unit as VTK's scalar opacity unit distance (VTK then corrects the
opacity as Beamcast does, 1 - (1 - a)^(step / unit)), the sample distance
(VTK's SampleDistance = Beamcast's step = smallest spacing /
samples_per_voxel; AutoAdjustSampleDistances off, ImageSampleDistance 1),
jittered ray starts in both (VTK's noise texture, Beamcast's per-pixel
noise) and VTK's early ray termination threshold (alpha > 1 - 1/255) as
Beamcast's `ert`. Both composite front to back with premultiplied colour.

What is compared: VTK's frame is 8-bit linear display values (its
framebuffer, no sRGB); Beamcast's scene has output tone "clamp", exposure 1,
and its float HDR buffer is clamped to [0, 1] (float, and rounded to 8 bits
like VTK's); the reference (`beamcast render --reference --hdr`, double, a
sixteenth of a voxel a step, no early termination) is clamped to [0, 1].
Relative L1 = sum |img - ref| / sum ref over pixels and channels; also the
8-bit max and RMS difference against round(255 ref).

Time per frame, medians over 9 rounds (--quick: 3), each round one Beamcast
frame and one VTK frame, so both see the same load on a shared machine, the
camera turned 0.5 degrees more each round. VTK (one worker process, two
warm-up frames per setting): Render() + WaitForCompletion() (the GPU frame),
and with the 8-bit read-back (GetPixelData). Beamcast (a process per round):
the frame rendered after a 16^2 warm-up camera (a batch of its own, so shader
compilation is not in the frame): the "volumes" pass's GPU time, the frame's
GPU time and its wall time (tone map and 8-bit read-back included); and, for
information, the per-frame share of 4-view batches (eight cameras of one
size in one scene: `render --json` reports each frame's share of its batch).
Ratios: VTK's time over Beamcast's at the same step, and at equal error: at
each Beamcast row's error + 2% (both errors of 8-bit frames), each tool's
time to reach it, log-log interpolated between its own rows.
Writes DIR/vtk_volumes.csv, DIR/vtk_volumes.md, DIR/vtk_volumes.png (error
against time) and per volume DIR/<volume>_side_by_side.png (reference,
Beamcast, VTK, both differences x 10) and each of those frames alone
(<volume>_reference.png, _beamcast.png, _vtk.png, _beamcast_diff_x10.png,
_vtk_diff_x10.png; linear values clamped to [0, 1], sRGB-encoded like
Beamcast's PNG), at 2 samples per voxel, jittered.
"""
import argparse
import csv
import gzip
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gi_bench import load_hdr, rel_l1, run_render  # noqa: E402
from povray_bench import time_to  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SYSTEM_PYTHON = "/usr/bin/python3"  # Debian's python3-vtk9 lives in its dist-packages
VTK_ERT = 1.0 - 1.0 / 255.0  # VTK's g_opacityThreshold: its early ray termination
WARM_SIZE = 16  # the warm-up camera's size (a batch of its own)
# Errors within 2% count as equal: near the 8-bit rounding floor both tools' errors
# differ in the fourth digit only, which a time-to-error interpolation would overread.
EQUAL_TOL = 0.02

# Transfer functions as [value, r, g, b, opacity]: Marschner-Lobb with
# protocol/volume.cpp's preset "ml"; the skull with a translucent bone (the
# preset "bone" turns opaque white by 0.5, which without shading shows only a
# flat silhouette: little for two ray casters to differ on).
ML_POINTS = [[0.0, 0.1, 0.2, 0.6, 0.0], [0.3, 0.2, 0.5, 1.0, 0.04],
             [0.45, 0.9, 0.9, 0.3, 0.1], [0.5, 1.0, 0.6, 0.1, 0.7],
             [0.55, 0.9, 0.25, 0.1, 0.1], [0.7, 0.8, 0.1, 0.3, 0.04],
             [1.0, 1.0, 1.0, 1.0, 0.0]]
SKULL_POINTS = [[0.0, 0.0, 0.0, 0.0, 0.0], [0.15, 0.3, 0.1, 0.1, 0.0],
                [0.25, 0.7, 0.35, 0.25, 0.03], [0.4, 0.9, 0.75, 0.55, 0.15],
                [0.6, 1.0, 0.95, 0.85, 0.4], [1.0, 1.0, 1.0, 1.0, 0.6]]


# ---------------------------------------------------------------------------
# The peer


def ensure_vtk():
    """python3-vtk9, xvfb-run and xauth, installed with apt-get when missing."""
    def have():
        ok = subprocess.run([SYSTEM_PYTHON, "-c", "import vtkmodules.vtkRenderingVolumeOpenGL2"],
                            capture_output=True).returncode == 0
        return ok and shutil.which("xvfb-run") and shutil.which("xauth")
    if have():
        return
    print("VTK or xvfb-run not found: installing them (apt-get install -y python3-vtk9 xvfb "
          "xauth)", flush=True)
    if os.geteuid() != 0:
        sys.exit("vtk_volume_bench: installing python3-vtk9 xvfb xauth needs root")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(["apt-get", "install", "-y", "-q", "python3-vtk9", "xvfb", "xauth"],
                   check=True, env=env, stdout=subprocess.DEVNULL)
    if not have():
        sys.exit("vtk_volume_bench: python3-vtk9 or xvfb-run still missing after apt-get install")


def vtk_version():
    p = subprocess.run([SYSTEM_PYTHON, "-c", "import vtk; print(vtk.vtkVersion.GetVTKVersion())"],
                       capture_output=True, text=True, check=True)
    return p.stdout.strip()


def vtk_worker():
    """The VTK side (run under xvfb-run): the first line on stdin is the job (volume,
    camera, size); then one command a line, `setting` (sample distance, jitter: two
    warm-up frames, then the frame at the job's camera saved as .npy, 8-bit RGB, rows
    top-down), `time` (one frame, the camera turned by `turn` degrees about its up
    through the target: Render() + WaitForCompletion(), then the read-back) or `quit`.
    Replies are single lines starting "@vtk " (VTK's own messages are other lines)."""
    import vtk
    from vtkmodules.util import numpy_support

    def reply(obj):
        sys.stdout.write("@vtk " + json.dumps(obj) + "\n")
        sys.stdout.flush()

    job = json.loads(sys.stdin.readline())
    vol = job["volume"]
    dims = vol["dimensions"]
    q = np.fromfile(vol["raw"], dtype="<u2")
    assert q.size == dims[0] * dims[1] * dims[2]
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.SetOrigin(*vol["origin"])
    image.SetSpacing(*vol["spacing"])
    image.GetPointData().SetScalars(
        numpy_support.numpy_to_vtk(q, deep=True, array_type=vtk.VTK_UNSIGNED_SHORT))

    ctf = vtk.vtkColorTransferFunction()
    otf = vtk.vtkPiecewiseFunction()
    for v, r, g, b, a in vol["points"]:  # Beamcast's range [0, 65535]: value x 65535
        ctf.AddRGBPoint(v * 65535.0, r, g, b)
        otf.AddPoint(v * 65535.0, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(vol["opacity_unit"])
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()

    mapper = vtk.vtkOpenGLGPUVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetBlendModeToComposite()
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetLockSampleDistanceToInputSpacing(0)
    mapper.SetImageSampleDistance(1.0)
    # The colour and opacity tables over the functions' own range, [0, 65535] as
    # Beamcast's, not the data's min to max.
    mapper.SetColorRangeType(vtk.vtkGPUVolumeRayCastMapper.NATIVE)
    mapper.SetScalarOpacityRangeType(vtk.vtkGPUVolumeRayCastMapper.NATIVE)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    size = job["size"]
    ren = vtk.vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    win.SetSize(size, size)
    win.AddRenderer(ren)
    cam_def = job["camera"]
    cam = ren.GetActiveCamera()

    def pose(turn_deg):
        cam.SetPosition(*cam_def["position"])
        cam.SetFocalPoint(*cam_def["target"])
        cam.SetViewUp(*cam_def["up"])
        cam.SetViewAngle(cam_def["fov_y"])  # vertical (UseHorizontalViewAngle off)
        if turn_deg:
            cam.Azimuth(turn_deg)  # about the view-up through the focal point
        cam.SetClippingRange(cam_def["near"], cam_def["far"])

    def pixels():
        arr = vtk.vtkUnsignedCharArray()
        win.GetPixelData(0, 0, size - 1, size - 1, 0, arr, 0)
        return numpy_support.vtk_to_numpy(arr).reshape(size, size, 3)[::-1].copy()

    pose(0.0)
    win.Render()
    caps = win.ReportCapabilities()
    reply({"renderer": " / ".join(line.split(":", 1)[1].strip() for line in caps.splitlines()
                                  if line.startswith(("OpenGL renderer", "OpenGL version")))})
    for line in sys.stdin:
        cmd = json.loads(line)
        if cmd["cmd"] == "setting":
            mapper.SetSampleDistance(cmd["sample_distance"])
            mapper.SetUseJittering(1 if cmd["jitter"] else 0)
            pose(0.0)
            for _ in range(2):  # warm-up: shader build, tables
                win.Render()
            win.WaitForCompletion()
            np.save(cmd["frame"], pixels())
            reply({"sample_distance": mapper.GetSampleDistance()})
        elif cmd["cmd"] == "time":
            pose(cmd["turn"])
            t0 = time.perf_counter()
            win.Render()
            win.WaitForCompletion()
            t1 = time.perf_counter()
            pixels()
            t2 = time.perf_counter()
            reply({"render_ms": (t1 - t0) * 1000, "total_ms": (t2 - t0) * 1000})
        else:
            reply({})
            return


class VtkPeer:
    """A VTK worker under xvfb-run for one volume, driven line by line."""

    def __init__(self, job):
        self.proc = subprocess.Popen(
            ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", SYSTEM_PYTHON,
             os.path.abspath(__file__), "--vtk-worker"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        self.renderer = self._send(job)["renderer"]

    def _send(self, obj):
        self.proc.stdin.write(json.dumps(obj) + "\n")
        self.proc.stdin.flush()
        for line in self.proc.stdout:
            if line.startswith("@vtk "):
                return json.loads(line[5:])
        raise RuntimeError("the VTK worker ended (exit %s)" % self.proc.wait())

    def setting(self, sample_distance, jitter, frame):
        return self._send({"cmd": "setting", "sample_distance": sample_distance,
                           "jitter": jitter, "frame": frame})["sample_distance"]

    def time(self, turn):
        return self._send({"cmd": "time", "turn": turn})

    def close(self):
        self._send({"cmd": "quit"})
        self.proc.wait()


# ---------------------------------------------------------------------------
# The volumes


def quantize16(t):
    """protocol/volume.cpp quantize: lround(t x 65535) of t in [0, 1]."""
    return np.floor(np.clip(t, 0.0, 1.0) * 65535.0 + 0.5).astype(np.uint16)


def marschner_lobb_grid(n):
    """procedural_grid(kMarschnerLobb, n): the field at -1 + 2i/(n-1) per axis, range
    [0, 1], 16 bits; the same expressions in the same order, shape (z, y, x)."""
    c = -1.0 + 2.0 * np.arange(n) / (n - 1)
    alpha, fm, pi = 0.25, 6.0, math.pi
    x, y = np.meshgrid(c, c, indexing="xy")  # [j, i]: y rows, x columns
    r = np.sqrt(x * x + y * y)
    xy = alpha * (1.0 + np.cos(2.0 * pi * fm * np.cos(pi * r / 2.0)))
    z = 1.0 - np.sin(pi * c / 2.0)
    rho = (z[:, None, None] + xy[None, :, :]) / (2.0 * (1.0 + alpha))
    return quantize16(rho)


def read_inr(path):
    """An INRIA image: `#INRIMAGE-4#{` header (a multiple of 256 bytes, up to `##}`),
    then the voxels, x fastest. Returns (array shaped (z, y, x), [vx, vy, vz])."""
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rb") as f:
        data = f.read()
    end = data.index(b"##}")
    header_len = (end + 3 + 255) // 256 * 256
    fields = {}
    for line in data[:end].decode("ascii", "replace").splitlines():
        if "=" in line and not line.startswith("#"):
            k, v = line.split("=", 1)
            fields[k.strip()] = v.strip()
    dims = [int(fields[k]) for k in ("XDIM", "YDIM", "ZDIM")]
    if int(fields.get("VDIM", "1")) != 1:
        raise ValueError("%s: VDIM %s (vector voxels)" % (path, fields["VDIM"]))
    bits = int(fields["PIXSIZE"].split()[0])
    big = fields.get("CPU", "decm").lower() in ("sun", "sgi")
    kind = {"float": "f", "unsigned fixed": "u", "signed fixed": "i"}[fields["TYPE"].lower()]
    dtype = np.dtype("%s%s%d" % (">" if big else "<", kind, bits // 8))
    count = dims[0] * dims[1] * dims[2]
    vox = np.frombuffer(data, dtype=dtype, count=count, offset=header_len)
    spacing = [float(fields.get(k, "1")) for k in ("VX", "VY", "VZ")]
    return vox.reshape(dims[2], dims[1], dims[0]), spacing


def quantize_like_beamcast(vox):
    """Float data at its default range (its own min and max) to 16 bits."""
    v = vox.astype(np.float64)
    lo, hi = float(v.min()), float(v.max())
    t = (v - lo) / (hi - lo) if hi > lo else np.zeros_like(v)
    return quantize16(t), [lo, hi]


def volume_setups(a, notes):
    """The volumes: name, the raw file's voxels, placement, transfer function, camera and
    the source Beamcast would read them from otherwise (for the identity check)."""
    out = []
    n = 41
    s = 2.0 / (n - 1)
    out.append({
        "name": "marschner_lobb", "label": "Marschner-Lobb 41^3", "voxels": marschner_lobb_grid(n),
        "spacing": [s, s, s], "points": ML_POINTS, "opacity_unit": 0.1,
        "camera": {"position": [2.6, -3.4, 2.0], "target": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0],
                   "fov_y": 45.0},
        "native": {"source": {"type": "marschner_lobb", "resolution": n}},
    })
    cgal = os.path.join(a.out, "cgal")
    p = subprocess.run([os.path.join(ROOT, "scripts", "fetch_cgal_volumes.sh"), cgal],
                       capture_output=True, text=True)
    skull = os.path.join(cgal, "skull_2.9.inr")
    if p.returncode != 0 or not os.path.exists(skull):
        said = (p.stderr or p.stdout).strip().splitlines()
        notes.append("skull skipped: scripts/fetch_cgal_volumes.sh failed (exit %d): %s" %
                     (p.returncode, said[-1] if said else "no message"))
        return out
    vox, spacing = read_inr(skull)
    q, rng = quantize_like_beamcast(vox)
    shutil.copy(skull, os.path.join(a.out, "skull_2.9.inr"))
    side = max((d - 1) * sp for d, sp in zip(q.shape[::-1], spacing))
    out.append({
        "name": "skull", "label": "skull 64^3 (skull_2.9.inr, float %.3g..%.3g)" % tuple(rng),
        "voxels": q, "spacing": spacing, "points": SKULL_POINTS, "opacity_unit": side / 20.0,
        "camera": {"position": [-150.0, -430.0, 110.0], "target": [0.0, 30.0, -10.0],
                   "up": [0.0, 0.0, 1.0], "fov_y": 45.0},
        "native": {"source": {"type": "inr", "file": "skull_2.9.inr"}},
    })
    return out


# ---------------------------------------------------------------------------
# Beamcast


def placement(v):
    dims = list(v["voxels"].shape[::-1])
    origin = [-(d - 1) * sp / 2.0 for d, sp in zip(dims, v["spacing"])]
    return dims, origin


# Beamcast's "volume.integration" (--integration): "point", its default, or
# "preintegrated".
INTEGRATION = {"value": "point"}


def scene_for(v, size, spv, jitter, cameras=None, native=False):
    dims, origin = placement(v)
    if native:  # the procedural or INR source, default range: for the identity check
        vol = dict(v["native"])
    else:
        vol = {"source": {"type": "raw", "file": v["name"] + ".raw", "dimensions": dims,
                          "format": "uint16", "endian": "little"},
               "range": [0, 65535]}
    vol.update({"origin": origin, "spacing": v["spacing"],
                "transfer": {"points": v["points"], "opacity_unit": v["opacity_unit"]},
                "intensity": 1.0})
    cam = dict(v["camera"], name="view", width=size, height=size, near=0.01, far=1000.0)
    return {"background": [0, 0, 0], "output": {"tone": "clamp", "exposure": 1.0},
            "volumes": [vol],
            "volume": {"samples_per_voxel": spv, "opacity_correction": True, "ert": VTK_ERT,
                       "jitter": jitter, "integration": INTEGRATION["value"]},
            "cameras": cameras(cam) if cameras else [cam]}


def beamcast_json(binary, scene, out_dir, assets):
    """`beamcast render --json` without --hdr (timing runs: 8-bit frames only)."""
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    p = subprocess.run([binary, "render", path, "--json", "-o", out_dir, "--assets", assets],
                       capture_output=True, text=True, check=True)
    return json.loads(p.stdout)


def pass_ms(frame, name):
    return sum(p["gpu_ms"] for p in frame.get("passes", []) if p["name"] == name)


def turned(cam, deg):
    """The camera turned about `up` through its target (VTK's Azimuth)."""
    p, t, u = (np.array(cam[k], float) for k in ("position", "target", "up"))
    u = u / np.linalg.norm(u)
    d = p - t
    th = math.radians(deg)
    d = d * math.cos(th) + np.cross(u, d) * math.sin(th) + u * np.dot(u, d) * (1 - math.cos(th))
    return dict(cam, position=list(t + d))


def time_both(a, v, spv, jitter, repeats, work, peer):
    """Frame times, Beamcast's and VTK's interleaved (the machine's load is shared):
    per round one Beamcast process rendering a 16^2 warm-up camera (a batch of its own,
    so shader compilation is not in the frame) and then the frame, and one VTK frame,
    both with the camera turned 0.5 degrees more; then a Beamcast process with eight
    cameras of the frame's size (two 4-view batches after the warm-up camera)."""
    singles, peer_times = [], []
    for i in range(repeats):
        turn = 0.5 * (i + 1)

        def cams(c, turn=turn):
            return [dict(c, name="warm", width=WARM_SIZE, height=WARM_SIZE),
                    dict(turned(c, turn), name="view")]
        summary = beamcast_json(a.binary, scene_for(v, a.size, spv, jitter, cams), work, a.out)
        singles.append(summary["frames"][1])
        peer_times.append(peer.time(turn))

    def batch_cams(c):
        return ([dict(c, name="warm", width=WARM_SIZE, height=WARM_SIZE)] +
                [dict(turned(c, 0.5 * (k + 1)), name="v%d" % k) for k in range(8)])
    summary = beamcast_json(a.binary, scene_for(v, a.size, spv, jitter, batch_cams), work, a.out)
    batched = summary["frames"][1:]
    return ({"volumes_ms": statistics.median(pass_ms(f, "volumes") for f in singles),
             "gpu_ms": statistics.median(f["gpu_ms"] for f in singles),
             "wall_ms": statistics.median(f["wall_ms"] for f in singles),
             "wall_min_ms": min(f["wall_ms"] for f in singles),
             "batch4_ms": statistics.median(f["wall_ms"] for f in batched),
             "renderer": summary.get("renderer", "")},
            {"render_ms": statistics.median(t["render_ms"] for t in peer_times),
             "total_ms": statistics.median(t["total_ms"] for t in peer_times),
             "total_min_ms": min(t["total_ms"] for t in peer_times)})


# ---------------------------------------------------------------------------
# Images and errors


def srgb8(linear):
    x = np.clip(linear, 0.0, 1.0)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.round(s * 255).astype(np.uint8)


def errors(img, ref):
    """rel L1 against the clamped reference, the 8-bit max and RMS against round(255 ref),
    the mean's ratio."""
    d8 = np.round(255 * img).astype(np.int32) - np.round(255 * ref).astype(np.int32)
    return {"rel_l1": round(rel_l1(img, ref), 5), "max8": int(np.abs(d8).max()),
            "rms8": round(float(np.sqrt(np.mean(d8.astype(np.float64) ** 2))), 3),
            "mean_ratio": round(float(img.mean() / ref.mean()), 4)}


def side_by_side(path, title, ref, bc, vk, amp):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = [("reference (CPU, double)", srgb8(ref)), ("Beamcast", srgb8(bc)),
              ("VTK 9.1", srgb8(vk)),
              ("|Beamcast - ref| x %d" % amp, srgb8(np.abs(bc - ref) * amp)),
              ("|VTK - ref| x %d" % amp, srgb8(np.abs(vk - ref) * amp))]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.6))
    for ax, (name, im) in zip(axes, panels):
        ax.imshow(im, interpolation="nearest")
        ax.set_title(name, fontsize=9)
        ax.axis("off")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def save_png(path, linear):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.imsave(path, srgb8(linear))


# ---------------------------------------------------------------------------


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "bin", "beamcast"))
    ap.add_argument("--out", help="output directory (required)")
    ap.add_argument("--size", type=int, default=None, help="image size (default 512; --quick 256)")
    ap.add_argument("--quick", action="store_true", help="256^2, fewer settings and repeats")
    ap.add_argument("--integration", choices=["point", "preintegrated"], default="point",
                    help="Beamcast's volume.integration (default point, its default)")
    ap.add_argument("--vtk-worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.vtk_worker:
        vtk_worker()
        return
    if not a.out:
        ap.error("--out DIR is required")
    a.size = a.size or (256 if a.quick else 512)
    INTEGRATION["value"] = a.integration
    a.out = os.path.abspath(a.out)
    a.binary = os.path.abspath(a.binary)
    os.makedirs(a.out, exist_ok=True)
    ensure_vtk()
    version = vtk_version()
    t_start = time.perf_counter()
    load_start = os.getloadavg()
    spvs = [0.25, 0.5, 1, 2, 4] if a.quick else [0.25, 0.5, 1, 2, 4, 8]
    repeats = a.rounds = 3 if a.quick else 9
    # (samples per voxel, jitter): the sweep with jittered starts, and the default
    # step without jitter in both.
    settings = [(s, True) for s in spvs] + [(2, False)]
    notes = []
    rows = []
    floors = {}
    bc_renderer = ""
    vtk_renderer = ""
    for v in volume_setups(a, notes):
        name = v["name"]
        dims, origin = placement(v)
        raw = os.path.join(a.out, name + ".raw")
        v["voxels"].astype("<u2").tofile(raw)
        step0 = min(v["spacing"])
        notes.append("%s: %s voxels (uint16 raw, range [0, 65535]), origin %s, spacing %s, "
                     "opacity unit %.4g, transfer points [value, r, g, b, opacity] %s, camera "
                     "%s" % (name, "x".join(map(str, dims)), [round(o, 6) for o in origin],
                             v["spacing"], v["opacity_unit"], v["points"],
                             json.dumps(dict(v["camera"], near=0.01, far=1000.0))))
        print("%s: %s voxels, spacing %s, opacity unit %.4g" %
              (name, "x".join(map(str, dims)), v["spacing"], v["opacity_unit"]), flush=True)

        # The same voxels: the tool's own source against the raw file, GPU, bit for bit.
        check = {}
        for kind in ("native", "raw"):
            s = scene_for(v, 96, 2, True, native=(kind == "native"))
            summary, _ = run_render(a.binary, s, os.path.join(a.out, "check_" + name, kind),
                                    ["--assets", a.out])
            check[kind] = load_hdr(summary["frames"][0])
        same = float(np.abs(check["native"] - check["raw"]).max())
        notes.append("%s: the %s source and the raw file give GPU frames (96^2) that differ by "
                     "at most %.3g (0: identical voxels)" %
                     (name, v["native"]["source"]["type"], same))

        ref_summary, _ = run_render(a.binary, scene_for(v, a.size, 2, True),
                                    os.path.join(a.out, "ref_" + name), ["--reference",
                                                                         "--assets", a.out])
        ref = np.clip(load_hdr(ref_summary["frames"][0]), 0.0, 1.0)
        ref_ms = ref_summary["frames"][0]["wall_ms"]
        floor = errors(np.round(ref * 255) / 255, ref)
        print("  reference %.1f s; its own 8-bit rounding: rel L1 %.5f" %
              (ref_ms / 1000, floor["rel_l1"]), flush=True)

        peer = VtkPeer({"volume": {"raw": raw, "dimensions": dims, "origin": origin,
                                   "spacing": v["spacing"], "points": v["points"],
                                   "opacity_unit": v["opacity_unit"]},
                        "camera": dict(v["camera"], near=0.01, far=1000.0), "size": a.size})
        vtk_renderer = peer.renderer

        frames = {}
        for k, (spv, jit) in enumerate(settings):
            setting = "%g samples/voxel (step %.4g)%s" % (spv, step0 / spv,
                                                          "" if jit else ", no jitter")
            bc_setting = setting + (", pre-integrated" if a.integration == "preintegrated" else "")
            # The frames for the error (Beamcast's HDR buffer; VTK's after its warm-up),
            # then the timing runs.
            summary, _ = run_render(a.binary, scene_for(v, a.size, spv, jit),
                                    os.path.join(a.out, "bc_%s_%d" % (name, k)),
                                    ["--assets", a.out])
            bc = np.clip(load_hdr(summary["frames"][0]), 0.0, 1.0)
            vtk_frame = os.path.join(a.out, "vtk_%s_%d.npy" % (name, k))
            vtk_step = peer.setting(step0 / spv, jit, vtk_frame)
            t, tv = time_both(a, v, spv, jit, repeats, os.path.join(a.out, "time_" + name), peer)
            bc_renderer = t["renderer"]
            e8 = errors(np.round(bc * 255) / 255, ref)
            rows.append({"tool": "Beamcast", "volume": name, "samples_per_voxel": spv,
                         "jitter": jit, "step": round(step0 / spv, 6),
                         "ms_frame": round(t["wall_ms"], 2),
                         "ms_frame_min": round(t["wall_min_ms"], 2),
                         "ms_render": round(t["gpu_ms"], 2),
                         "ms_volume_pass": round(t["volumes_ms"], 2),
                         "ms_batch4": round(t["batch4_ms"], 2),
                         "rel_l1": e8["rel_l1"], "rel_l1_float": errors(bc, ref)["rel_l1"],
                         "max8": e8["max8"], "rms8": e8["rms8"], "mean_ratio": e8["mean_ratio"],
                         "setting": bc_setting})
            print(json.dumps(rows[-1]), flush=True)
            vk = np.load(vtk_frame).astype(np.float64) / 255.0
            e = errors(vk, ref)
            rows.append({"tool": "VTK " + version, "volume": name, "samples_per_voxel": spv,
                         "jitter": jit, "step": round(vtk_step, 6),
                         "ms_frame": round(tv["total_ms"], 2),
                         "ms_frame_min": round(tv["total_min_ms"], 2),
                         "ms_render": round(tv["render_ms"], 2),
                         "ms_volume_pass": "", "ms_batch4": "",
                         "rel_l1": e["rel_l1"], "rel_l1_float": "", "max8": e["max8"],
                         "rms8": e["rms8"], "mean_ratio": e["mean_ratio"], "setting": setting})
            print(json.dumps(rows[-1]), flush=True)
            frames[(spv, jit)] = (bc, vk)
        peer.close()
        bc, vk = frames[(2, True)]
        save_png(os.path.join(a.out, name + "_reference.png"), ref)
        save_png(os.path.join(a.out, name + "_beamcast.png"), bc)
        save_png(os.path.join(a.out, name + "_vtk.png"), vk)
        save_png(os.path.join(a.out, name + "_beamcast_diff_x10.png"), np.abs(bc - ref) * 10)
        save_png(os.path.join(a.out, name + "_vtk_diff_x10.png"), np.abs(vk - ref) * 10)
        side_by_side(os.path.join(a.out, name + "_side_by_side.png"),
                     "%s, %d^2, 2 samples/voxel, jittered; linear values clamped to [0, 1], "
                     "shown sRGB-encoded" % (v["label"], a.size), ref, bc, vk, 10)
        notes.append("%s: the reference took %.1f s; rounding it to 8 bits alone gives rel L1 "
                     "%.5f (the floor of the 8-bit columns)" %
                     (name, ref_ms / 1000, floor["rel_l1"]))
        floors[name] = floor["rel_l1"]

    write_outputs(a, rows, floors, notes, version, bc_renderer, vtk_renderer, load_start,
                  t_start)


def envelope(sel, key):
    """(time, error) of rows as povray_bench.time_to takes them, the error made the best
    so far in time order (a tool reaches an error once any cheaper row of it has)."""
    pts, best = [], math.inf
    for r in sorted(sel, key=lambda r: r[key]):
        best = min(best, r["rel_l1"])
        pts.append({"time_s": r[key], "rel_l1": best})
    return pts


def equal_error(rows):
    """Per Beamcast row (jittered): VTK's row at the same step; and at equal error,
    target = the row's rel L1 + EQUAL_TOL, each tool's time to reach it over its own
    rows (log-log interpolation; a row of the tool already as accurate for less time
    counts) and the ratio."""
    out = []
    for name in sorted({r["volume"] for r in rows}):
        def pick(beamcast):
            return [r for r in rows if r["volume"] == name and r["jitter"] and
                    (r["tool"] == "Beamcast") == beamcast]
        ours, peer = pick(True), pick(False)
        for r in ours:
            same = next(p for p in peer if p["samples_per_voxel"] == r["samples_per_voxel"])
            target = r["rel_l1"] * (1 + EQUAL_TOL)
            t = {key: (time_to(envelope(ours, key), target), time_to(envelope(peer, key), target))
                 for key in ("ms_frame", "ms_frame_min")}
            t_ours, t_peer = t["ms_frame"]
            t_ours_min, t_peer_min = t["ms_frame_min"]
            out.append({"volume": name, "samples_per_voxel": r["samples_per_voxel"],
                        "rel_l1": r["rel_l1"], "vtk_rel_l1": same["rel_l1"],
                        "beamcast_ms": r["ms_frame"], "vtk_same_ms": same["ms_frame"],
                        "same_ratio": same["ms_frame"] / r["ms_frame"], "target": target,
                        "beamcast_to": t_ours, "vtk_to": t_peer,
                        "ratio": t_peer / t_ours if t_peer else None,
                        "ratio_min": t_peer_min / t_ours_min if t_peer_min else None})
    return out


def write_outputs(a, rows, floors, notes, version, bc_renderer, vtk_renderer, load_start,
                  t_start):
    cols = ["tool", "volume", "samples_per_voxel", "jitter", "step", "ms_frame", "ms_frame_min",
            "ms_render",
            "ms_volume_pass", "ms_batch4", "rel_l1", "rel_l1_float", "max8", "rms8", "mean_ratio"]
    with open(os.path.join(a.out, "vtk_volumes.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols + ["setting"])
        w.writeheader()
        w.writerows(rows)
    eq = equal_error(rows)
    load_end = os.getloadavg()
    with open(os.path.join(a.out, "vtk_volumes.md"), "w") as f:
        f.write("Volume ray casting beside VTK %s's GPU ray cast mapper, %dx%d, one run "
                "(%.0f s; load average %.2f at the start, %.2f at the end, %d cores).\n\n" %
                (version, a.size, a.size, time.perf_counter() - t_start, load_start[0],
                 load_end[0], os.cpu_count() or 0))
        st = os.stat(a.binary)
        f.write("- Beamcast: %s (EGL, no X); %s, %d bytes, modified %s\n- VTK: %s (GLX under "
                "xvfb-run)\n\n" % (bc_renderer, a.binary, st.st_size,
                                    time.strftime("%Y-%m-%d %H:%M", time.localtime(st.st_mtime)),
                                    vtk_renderer))
        f.write("Error: relative L1 against `beamcast render --reference` (double, step a "
                "sixteenth of a voxel, no early termination), all linear values clamped to "
                "[0, 1]; `rel_l1` compares 8-bit frames (VTK's framebuffer; Beamcast's HDR "
                "buffer rounded to 8 bits), `rel_l1_float` Beamcast's float frame; max8 and "
                "rms8 in 8-bit steps against round(255 ref); mean_ratio the mean over the "
                "reference's (below 1: too transparent or too dark).\n\n")
        f.write("Time (ms): `ms_frame` the whole frame into client memory, 8-bit (Beamcast: "
                "the frame's wall time, tone map and read-back included, after a warm-up "
                "camera; VTK: Render() + WaitForCompletion() + GetPixelData); `ms_render` the "
                "GPU frame (Beamcast: the frame's GPU time; VTK: Render() + "
                "WaitForCompletion()); `ms_volume_pass` Beamcast's \"volumes\" pass alone; "
                "`ms_batch4` Beamcast's per-frame share of 4-view batches (for information: "
                "VTK renders one view at a time). Medians over %d rounds (`ms_frame_min` the "
                "fastest round: the others' builds share this machine's cores), each round one "
                "frame of each tool, the camera turned 0.5 degrees a round.\n\n" % a.rounds)
        show = ["tool", "volume", "setting", "ms_frame", "ms_frame_min", "ms_render",
                "ms_volume_pass",
                "ms_batch4", "rel_l1", "rel_l1_float", "max8", "rms8", "mean_ratio"]
        f.write("| " + " | ".join(show) + " |\n|" + "---|" * len(show) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r[c]) for c in show) + " |\n")
        f.write("\nBeamcast against VTK (8-bit frames, jittered rows; ratios are VTK's time "
                "over Beamcast's, above 1: Beamcast faster). Same step: the two rows of a "
                "setting. Equal error: the target is each Beamcast row's rel L1 + %d%% (near "
                "the 8-bit floor the two tools differ in the fourth digit only); each tool's "
                "time to reach it, log-log interpolated between its own rows (a cheaper row "
                "of its own already as accurate counts); \"not reached\" when no VTK row is "
                "that accurate.\n\n" % round(EQUAL_TOL * 100))
        f.write("| volume | samples/voxel | Beamcast rel L1 | VTK rel L1 | Beamcast ms | VTK ms | "
                "VTK / Beamcast, same step | target rel L1 | Beamcast ms to target | VTK ms to "
                "target | VTK / Beamcast, equal error | the same, fastest rounds |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for e in eq:
            f.write("| %s | %g | %.5f | %.5f | %.1f | %.1f | %.2f | %.5f | %.1f | %s | %s | %s "
                    "|\n" %
                    (e["volume"], e["samples_per_voxel"], e["rel_l1"], e["vtk_rel_l1"],
                     e["beamcast_ms"], e["vtk_same_ms"], e["same_ratio"], e["target"],
                     e["beamcast_to"], "%.1f" % e["vtk_to"] if e["vtk_to"] else "not reached",
                     "%.2f" % e["ratio"] if e["ratio"] else "not reached",
                     "%.2f" % e["ratio_min"] if e["ratio_min"] else "not reached"))
        f.write("\nNotes:\n\n")
        for n in notes:
            f.write("- %s\n" % n)
    print(open(os.path.join(a.out, "vtk_volumes.md")).read(), flush=True)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    names = sorted({r["volume"] for r in rows})
    fig, axes = plt.subplots(1, len(names), figsize=(5.5 * len(names), 4.2), squeeze=False)
    for ax, name in zip(axes[0], names):
        for tool, mark in (("Beamcast", "o-"), ("VTK", "^--")):
            sel = sorted((r for r in rows if r["volume"] == name and r["jitter"] and
                          r["tool"].startswith(tool)), key=lambda r: r["samples_per_voxel"])
            ax.loglog([r["ms_frame"] for r in sel], [r["rel_l1"] for r in sel], mark,
                      label=sel[0]["tool"] if sel else tool)
            for r in sel:
                ax.annotate("%g" % r["samples_per_voxel"], (r["ms_frame"], r["rel_l1"]),
                            fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.axhline(floors[name], color="grey", ls=":", label="8-bit rounding of the reference")
        ax.set_xlabel("ms per frame (llvmpipe, this machine)")
        ax.set_ylabel("relative L1 against the CPU reference (8-bit frames)")
        ax.set_title("%s %d²: labels are samples per voxel" % (name, a.size), fontsize=9)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "vtk_volumes.png"), dpi=110)


if __name__ == "__main__":
    main()
