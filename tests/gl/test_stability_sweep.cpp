// Property-based sweep over random (scene, camera) configurations drawn to hit
// the hard regions of issue 5; each is rendered on the GPU path and by the CPU
// reference in double. Checks: no NaN or Inf anywhere in the HDR buffer, no
// negative energy, and the error against the reference within the bound below.
//
// Replay: scene n (configurations 8n .. 8n + 7, one scene and its 8 cameras)
// is drawn from its own generator seeded with (seed, n), so
// BEAMCAST_SWEEP_SEED=<seed> BEAMCAST_SWEEP_FIRST=<k> BEAMCAST_SWEEP_SIZE=1
// renders the scene of configuration k again (BEAMCAST_SWEEP_VERBOSE=1 prints
// every pixel of a failing one). BEAMCAST_SWEEP_SIZE sets how many
// configurations run (default 100000), BEAMCAST_SWEEP_GROUP=<0..7> keeps one
// group, BEAMCAST_SWEEP_NEAR_PARALLEL=none renders with the paper's form.
//
// Cost: each configuration is a tiny image (8x8 pixels mostly; 1x1, 1x16, 16x1
// and 3x7 for the extreme cameras) and scenes hold several cameras, so one
// render call renders a batch; the reference renders every pixel of every
// configuration (no subsampling), in parallel with the GPU frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "protocol/camera.hpp"
#include "render/image.hpp"
#include "render/lut.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {
namespace {

constexpr double kPi = std::numbers::pi;

using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
double log_uniform(Rng& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}
int pick(Rng& rng, int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }
bool chance(Rng& rng, double p) { return uniform(rng, 0.0, 1.0) < p; }

Vec3 unit_vector(Rng& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3 v{n(rng), n(rng), n(rng)};
    if (length(v) > 1e-3) return normalize(v);
  }
}

// A unit vector at angle theta from `axis` (unit), azimuth random.
Vec3 at_angle(Rng& rng, const Vec3& axis, double theta) {
  Vec3 u = cross(axis, unit_vector(rng));
  while (length(u) < 1e-3) u = cross(axis, unit_vector(rng));
  u = normalize(u);
  return std::cos(theta) * axis + std::sin(theta) * u;
}

// ---------------------------------------------------------------------------
// Densities: the built-ins and two user tables with a step (a ramp one sample
// wide, the steepest a table can hold) at different places.

Density density_named(const char* name) {
  Density d;
  if (!density_from_name(name, &d)) std::abort();
  return d;
}

Density step_table(int variant) {
  Density d;
  d.kind = DensityKind::kTable;
  if (variant == 0) {
    d.samples = {1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0};  // a step over one sample: 0.4 .. 0.5
  } else {
    // A step over 0.01 (slope 100, the thin shell's flanks) at x = 0.55, and
    // a spike of 5 on 0.75 .. 0.8 with flanks as steep.
    d.samples.assign(101, 0.0);
    for (int i = 0; i <= 55; ++i) d.samples[i] = 1.0;
    for (int i = 75; i <= 80; ++i) d.samples[i] = 5.0;
  }
  return d;
}

Density random_density(Rng& rng) {
  switch (pick(rng, 7)) {
    case 0: return density_named("abe");
    case 1: return density_named("shell");
    case 2: return density_named("linear");
    case 3: return density_named("quadratic");
    case 4: return density_named("gaussian");
    case 5: return step_table(0);
    default: return step_table(1);
  }
}

Beam sphere_beam(Vec3 c, double r, Density d) {
  Beam b;
  b.shape = SphereBeam{c};
  b.radius = r;
  b.density = std::move(d);
  return b;
}

Beam capsule_beam(Vec3 p0, Vec3 p1, double r, Density d, bool cap0 = true, bool cap1 = true) {
  Beam b;
  b.shape = CapsuleBeam{p0, p1, cap0, cap1};
  b.radius = r;
  b.density = std::move(d);
  return b;
}

Beam random_beam(Rng& rng, Density d) {
  const Vec3 c{uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5)};
  const double r = uniform(rng, 0.3, 1.2);
  if (chance(rng, 0.4)) return sphere_beam(c, r, std::move(d));
  const Vec3 axis = unit_vector(rng);
  const Vec3 half = uniform(rng, 0.05, 2.0) * axis;
  const bool cap1 = chance(rng, 0.8), cap0 = chance(rng, 0.8);
  return capsule_beam(c - half, c + half, r, std::move(d), cap0, cap1);
}

// ---------------------------------------------------------------------------
// Cameras, in the configuration's own frame (radius about 1 at the origin).

Vec3 up_for(Rng& rng, const Vec3& forward) {
  for (;;) {
    const Vec3 u = unit_vector(rng);
    if (std::abs(dot(u, forward)) < 0.9) return u;
  }
}

Camera camera_towards(Rng& rng, Vec3 pos, Vec3 dir, double fov, int w = 8, int h = 8) {
  Camera c;
  c.position = pos;
  c.target = pos + dir;
  c.up = up_for(rng, dir);
  c.fov_y_deg = fov;
  c.width = w;
  c.height = h;
  c.near_plane = 1e-4;
  c.far_plane = 1e4;
  return c;
}

Camera ortho_towards(Rng& rng, Vec3 pos, Vec3 dir, double height) {
  Camera c = camera_towards(rng, pos, dir, 45.0);
  c.projection = Projection::kOrthographic;
  c.ortho_height = height;
  return c;
}

// Perspective camera at `pos` whose view of a ball (centre c, radius r) fills
// about `fill` of the image height.
Camera camera_seeing(Rng& rng, Vec3 pos, Vec3 c, double r, double fill = 1.0) {
  const double dist = length(c - pos);
  const double half = std::atan(std::min(r / dist, 1.0) / fill);
  return camera_towards(rng, pos, normalize(c - pos), std::clamp(2 * half * 180 / kPi, 0.01, 170.0));
}

Occluder sphere_occluder(Vec3 c, double r) {
  Occluder o;
  o.shape = SphereOccluder{c, r};
  return o;
}
Occluder plane_occluder(Vec3 p, Vec3 n) {
  Occluder o;
  o.shape = PlaneOccluder{p, n};
  return o;
}

// ---------------------------------------------------------------------------
// Configurations. A group draws one scene and kCamerasPerScene cameras for it
// in a frame where the beams have radius ~1 near the origin; place() then
// rotates, scales (radii 1e-6 .. 1e6) and moves it (up to 1e5 from the
// origin) as a whole.
// Each random number is drawn in a statement of its own or in a braced list
// (both evaluated in order), never two in one call's arguments or one
// product's operands, whose order C++ leaves to the compiler (g++ and clang
// differ): so a configuration number names the same scene in every build.
// The statements keep the order g++ drew them in before, so the numbers of
// earlier runs (55288 below) still name the same configurations.

constexpr int kCamerasPerScene = 8;

struct Draw {
  std::string what;  // the group's parameters, printed when a check fails
  Scene scene;
};

enum Group {
  kNearParallel,
  kCameraOnBeam,
  kScales,
  kGrazing,
  kJumpsAndCores,
  kCoincident,
  kOccluders,
  kExtremeCameras,
  kGroupCount
};
const char* const kGroupNames[kGroupCount] = {
    "near-parallel (1e-7 rad .. 90 deg)", "camera inside / on surface, axis, end plane",
    "distances 1e-3 .. 1e6",              "grazing d' -> 1",
    "jumps, spikes, abe core",            "coincident / overlapping beams",
    "occluders inside beams",             "extreme fov, near, far, sizes"};

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

Draw draw_near_parallel(Rng& rng) {
  Draw d;
  const double h = uniform(rng, 0.5, 5.0);
  const bool c0 = chance(rng, 0.75), c1 = chance(rng, 0.75);
  const Density dens = random_density(rng);
  d.scene.beams = {capsule_beam({0, 0, -h}, {0, 0, h}, 1.0, dens, c0, c1)};
  d.what = "capsule half-length " + fmt("%.3g", h) + " " + dens.name();
  for (int k = 0; k < kCamerasPerScene; ++k) {
    const double theta = chance(rng, 0.05) ? 0.0 : log_uniform(rng, 1e-7, kPi / 2);
    Vec3 axis{0, 0, chance(rng, 0.5) ? 1.0 : -1.0};
    const Vec3 v = at_angle(rng, axis, theta);
    const double rho = uniform(rng, 0.0, 0.95), phi = uniform(rng, 0, 2 * kPi);
    const Vec3 aim{rho * std::cos(phi), rho * std::sin(phi), uniform(rng, -h, h)};
    // Outside (through the end cap for small angles) or inside the capsule.
    const double back = chance(rng, 0.5) ? uniform(rng, h + 2.0, 3 * h + 10) : uniform(rng, 0.01, 0.5);
    const Vec3 pos = aim - back * v;
    d.scene.cameras.push_back(chance(rng, 0.5) ? ortho_towards(rng, pos, v, uniform(rng, 0.2, 3.0))
                                               : camera_towards(rng, pos, v, uniform(rng, 1.0, 90.0)));
  }
  return d;
}

Draw draw_camera_on_beam(Rng& rng) {
  Draw d;
  const Density dens = random_density(rng);
  const double h = uniform(rng, 0.2, 3.0);
  const bool sphere = chance(rng, 0.4);
  d.scene.beams = {sphere ? sphere_beam({0, 0, 0}, 1.0, dens)
                          : capsule_beam({0, 0, -h}, {0, 0, h}, 1.0, dens)};
  d.what = std::string(sphere ? "sphere " : "capsule ") + dens.name();
  for (int k = 0; k < kCamerasPerScene; ++k) {
    Vec3 pos;
    const Vec3 n = unit_vector(rng);
    const double z = sphere ? 0.0 : uniform(rng, -h, h);
    switch (pick(rng, 4)) {
      case 0:  // centre
        pos = {0, 0, 0};
        break;
      case 1:  // on the surface (radial unit vector; on the cylinder for a capsule)
        pos = sphere ? n : normalize(Vec3{n[0], n[1], 0.0}) + Vec3{0, 0, z};
        break;
      case 2:  // on the axis
        pos = {0, 0, z};
        break;
      default:  // on an end plane, inside or outside the radius
        pos = {uniform(rng, -1.2, 1.2), 0, sphere ? 0.0 : h};
        break;
    }
    const double fov = uniform(rng, 20.0, 120.0);
    const Vec3 dir = unit_vector(rng);
    d.scene.cameras.push_back(camera_towards(rng, pos, dir, fov));
  }
  return d;
}

Draw draw_scales(Rng& rng) {
  Draw d;
  const Density dens = random_density(rng);
  d.scene.beams = {sphere_beam({0, 0, 0}, 1.0, dens)};
  // A second beam of a very different radius in the same scene.
  const double r2 = log_uniform(rng, 1e-3, 1e3);
  d.scene.beams.push_back(capsule_beam({1.0, 0, 0}, {1.0 + r2, r2, 0}, r2, random_density(rng)));
  d.what = "sphere " + dens.name() + ", capsule radius " + fmt("%.3g", r2);
  for (int k = 0; k < kCamerasPerScene; ++k) {
    const double dist = log_uniform(rng, 1e-3, 1e6);
    const Vec3 pos = (1.0 + dist) * unit_vector(rng);
    Camera cam = camera_seeing(rng, pos, {0, 0, 0}, 1.0, uniform(rng, 0.3, 3.0));
    cam.near_plane = std::min(1e-4, 0.5 * dist);
    cam.far_plane = 10 * (1 + dist + r2);
    d.scene.cameras.push_back(cam);
  }
  return d;
}

Draw draw_grazing(Rng& rng) {
  Draw d;
  const Density dens = random_density(rng);
  const bool sphere = chance(rng, 0.5);
  d.scene.beams = {sphere ? sphere_beam({0, 0, 0}, 1.0, dens)
                          : capsule_beam({0, 0, -2}, {0, 0, 2}, 1.0, dens)};
  d.what = std::string(sphere ? "sphere " : "capsule ") + dens.name();
  for (int k = 0; k < kCamerasPerScene; ++k) {
    // A view direction across the axis (capsule) and a central ray passing at
    // d' = 1 -+ eps from the centre or the axis.
    const double eps_size = log_uniform(rng, 1e-7, 1e-1);
    const double eps = eps_size * (chance(rng, 0.8) ? 1.0 : -1.0);
    const Vec3 v = sphere ? unit_vector(rng) : at_angle(rng, {0, 0, 1}, uniform(rng, 0.3, kPi / 2));
    Vec3 side = cross(v, sphere ? unit_vector(rng) : Vec3{0, 0, 1});
    side = normalize(side);
    const Vec3 pass = (1.0 - eps) * side + Vec3{0, 0, sphere ? 0.0 : uniform(rng, -1.5, 1.5)};
    const Vec3 pos = pass - uniform(rng, 2.5, 10.0) * v;
    d.scene.cameras.push_back(camera_towards(rng, pos, v, log_uniform(rng, 0.01, 5.0)));
  }
  return d;
}

Draw draw_jumps(Rng& rng) {
  Draw d;
  Density dens;
  switch (pick(rng, 4)) {
    case 0: dens = density_named("shell"); break;
    case 1: dens = step_table(0); break;
    case 2: dens = step_table(1); break;
    default: dens = density_named("abe"); break;
  }
  d.scene.beams = {chance(rng, 0.5) ? sphere_beam({0, 0, 0}, 1.0, dens)
                                    : capsule_beam({0, 0, 0}, {0, 0, 0.01}, 1.0, dens)};
  d.what = dens.name();
  for (int k = 0; k < kCamerasPerScene; ++k) {
    // Rays through the centre (the abe core at x <= 0.01) or across the jump.
    const Vec3 pos_dir = unit_vector(rng);
    const Vec3 pos = uniform(rng, 1.5, 10.0) * pos_dir;
    const bool core = chance(rng, 0.5);
    const Vec3 aim_dir = unit_vector(rng);
    const Vec3 aim = (core ? log_uniform(rng, 1e-4, 0.02) : uniform(rng, 0.6, 0.9)) * aim_dir;
    d.scene.cameras.push_back(camera_towards(rng, pos, normalize(aim - pos), log_uniform(rng, 0.05, 30.0)));
  }
  return d;
}

Draw draw_coincident(Rng& rng) {
  Draw d;
  const Beam base = random_beam(rng, random_density(rng));
  const int n = chance(rng, 0.1) ? 100 : 2 + pick(rng, 6);
  const double jitter = chance(rng, 0.5) ? 0.0 : log_uniform(rng, 1e-9, 1e-3);
  for (int i = 0; i < n; ++i) {
    Beam b = base;
    const Vec3 off = jitter * unit_vector(rng);
    if (auto* s = std::get_if<SphereBeam>(&b.shape)) {
      s->center = s->center + off;
    } else {
      auto& c = std::get<CapsuleBeam>(b.shape);
      c.p0 = c.p0 + off;
      c.p1 = c.p1 + off;
    }
    d.scene.beams.push_back(b);
  }
  d.what = std::to_string(n) + " beams " + base.density.name() + " jitter " + fmt("%.2g", jitter);
  for (int k = 0; k < kCamerasPerScene; ++k) {
    const Vec3 dir = unit_vector(rng);
    const Vec3 pos = uniform(rng, 0.2, 6.0) * dir;
    d.scene.cameras.push_back(camera_seeing(rng, pos, {0, 0, 0}, 2.0));
  }
  return d;
}

Draw draw_occluders(Rng& rng) {
  Draw d;
  const Beam b = random_beam(rng, random_density(rng));
  d.scene.beams = {b};
  const Vec3 in_dir = unit_vector(rng);
  const Vec3 in = uniform(rng, 0.0, 0.6) * in_dir;  // a point inside the beam
  std::vector<Camera> cams;
  for (int k = 0; k < kCamerasPerScene; ++k) {
    const Vec3 pos_dir = unit_vector(rng);
    const Vec3 pos = (chance(rng, 0.3) ? uniform(rng, 0.0, 0.8) : uniform(rng, 2.0, 6.0)) * pos_dir;
    const double fov = uniform(rng, 20.0, 100.0);
    const Vec3 wobble = unit_vector(rng);
    cams.push_back(camera_towards(rng, pos, normalize(in - pos + 0.3 * wobble), fov));
  }
  switch (pick(rng, 4)) {
    case 0:
      d.scene.occluders = {sphere_occluder(in, log_uniform(rng, 1e-3, 0.5))};
      d.what = "ball inside the beam";
      break;
    case 1:
      d.scene.occluders = {plane_occluder(in, unit_vector(rng))};
      d.what = "plane through the beam";
      break;
    case 2:  // through the first camera: clipped by its near plane there
      d.scene.occluders = {plane_occluder(cams[0].position, unit_vector(rng))};
      d.what = "plane through a camera";
      break;
    default:  // behind every camera's far plane
      for (auto& c : cams) c.far_plane = 10.0;
      d.scene.occluders = {plane_occluder({0, 0, -40}, {0, 0, 1}), sphere_occluder({0, 50, 0}, 20)};
      d.what = "occluders behind the far plane";
      break;
  }
  d.what += ", " + b.density.name();
  d.scene.cameras = std::move(cams);
  return d;
}

Draw draw_extreme_cameras(Rng& rng) {
  Draw d;
  d.scene.beams = {random_beam(rng, random_density(rng)), random_beam(rng, random_density(rng))};
  d.what = "two beams";
  static constexpr int kSizes[][2] = {{8, 8}, {1, 1}, {1, 16}, {16, 1}, {3, 7}};
  for (int k = 0; k < kCamerasPerScene; ++k) {
    const int* wh = kSizes[pick(rng, 5)];
    Camera cam;
    switch (pick(rng, 4)) {
      case 0: {  // tiny fov
        const Vec3 pos_dir = unit_vector(rng);
        const Vec3 pos = uniform(rng, 2.0, 20.0) * pos_dir;
        const double fov = log_uniform(rng, 0.01, 0.5);
        const Vec3 aim = 0.5 * unit_vector(rng);
        cam = camera_towards(rng, pos, normalize(aim - pos), fov, wh[0], wh[1]);
        break;
      }
      case 1: {  // huge fov, from inside or next to a beam
        const Vec3 pos_dir = unit_vector(rng);
        const Vec3 pos = uniform(rng, 0.0, 1.5) * pos_dir;
        const double fov = uniform(rng, 150.0, 179.0);
        const Vec3 dir = unit_vector(rng);
        cam = camera_towards(rng, pos, dir, fov, wh[0], wh[1]);
        break;
      }
      case 2: {  // orthographic, any height
        const Vec3 v = unit_vector(rng);
        const double height = log_uniform(rng, 1e-3, 10.0);
        const double back = uniform(rng, 0.0, 8.0);
        const Vec3 side_dir = unit_vector(rng);
        const Vec3 side = uniform(rng, -0.5, 0.5) * side_dir;
        cam = ortho_towards(rng, side - back * v, v, height);
        cam.width = wh[0];
        cam.height = wh[1];
        break;
      }
      default: {  // near 1e-6, far 1e9 (the largest ratio validation accepts is 1e15)
        const Vec3 pos_dir = unit_vector(rng);
        const Vec3 pos = uniform(rng, 0.5, 6.0) * pos_dir;
        cam = camera_seeing(rng, pos, {0, 0, 0}, 1.5);
        cam.width = wh[0];
        cam.height = wh[1];
        break;
      }
    }
    if (chance(rng, 0.5)) {
      cam.near_plane = 1e-6;
      cam.far_plane = 1e9;
    }
    d.scene.cameras.push_back(cam);
  }
  return d;
}

// Rotation by q, scale by s, then translation by t, of every position, size and
// camera of the scene (a similarity leaves the exact image unchanged).
void place(Scene& scene, const std::array<double, 4>& q, double s, const Vec3& t) {
  auto pt = [&](const Vec3& p) { return t + s * rotate(q, p); };
  for (Beam& b : scene.beams) {
    b.radius *= s;
    if (auto* sp = std::get_if<SphereBeam>(&b.shape)) {
      sp->center = pt(sp->center);
    } else {
      auto& c = std::get<CapsuleBeam>(b.shape);
      c.p0 = pt(c.p0);
      c.p1 = pt(c.p1);
    }
  }
  for (Occluder& o : scene.occluders) {
    if (auto* p = std::get_if<PlaneOccluder>(&o.shape)) {
      p->point = pt(p->point);
      p->normal = rotate(q, p->normal);
    } else if (auto* b = std::get_if<SphereOccluder>(&o.shape)) {
      b->center = pt(b->center);
      b->radius *= s;
    }
  }
  for (Camera& c : scene.cameras) {
    const Vec3 dir = *c.target - c.position;
    c.position = pt(c.position);
    c.target = c.position + s * rotate(q, dir);
    c.up = rotate(q, c.up);
    c.near_plane *= s;
    c.far_plane *= s;
    c.ortho_height *= s;
  }
}

struct Batch {
  int group = 0;
  std::uint64_t index = 0;  // batch number; configurations index * kCamerasPerScene + k
  Draw draw;
  double scale = 1.0;
  double offset = 0.0;
};

Batch make_batch(std::uint64_t seed, std::uint64_t index) {
  // One generator per batch: a failure replays from (seed, index) alone.
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32)};
  Rng rng(seq);
  Batch b;
  b.index = index;
  b.group = static_cast<int>(index % kGroupCount);
  switch (b.group) {
    case kNearParallel: b.draw = draw_near_parallel(rng); break;
    case kCameraOnBeam: b.draw = draw_camera_on_beam(rng); break;
    case kScales: b.draw = draw_scales(rng); break;
    case kGrazing: b.draw = draw_grazing(rng); break;
    case kJumpsAndCores: b.draw = draw_jumps(rng); break;
    case kCoincident: b.draw = draw_coincident(rng); break;
    case kOccluders: b.draw = draw_occluders(rng); break;
    default: b.draw = draw_extreme_cameras(rng); break;
  }
  // Half the scenes at unit scale at the origin; the others scaled by
  // 1e-6 .. 1e6 and moved up to 1e5 away (offset / scale <= 1e11 keeps the
  // double inputs exact to ~1e-5 of a radius, for both renderers alike).
  std::normal_distribution<double> n;
  std::array<double, 4> q{n(rng), n(rng), n(rng), n(rng)};
  const double ql = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& x : q) x /= ql;
  if (chance(rng, 0.5)) {
    // Cameras of the distances group stand up to 1e6 radii away: scaled by
    // at most 1e4 they stay within validation's 1e12 coordinate limit.
    b.scale = log_uniform(rng, 1e-6, b.group == kScales ? 1e4 : 1e6);
    b.offset = chance(rng, 0.5) ? log_uniform(rng, 1.0, 1e5) : 0.0;
  }
  place(b.draw.scene, q, b.scale, b.offset * unit_vector(rng));
  for (Beam& beam : b.draw.scene.beams) {
    beam.color = {uniform(rng, 0.2, 1.0), uniform(rng, 0.2, 1.0), uniform(rng, 0.2, 1.0)};
  }
  return b;
}

// ---------------------------------------------------------------------------
// Checking one configuration.

// The energy scale of a scene: per beam, its brightest channel times the
// energy of a ray through the centre of a sphere of that density (the
// diameter integral, g(0, 2)), summed over the beams (coincident beams add).
double energy_scale(const Scene& scene) {
  static std::map<std::string, double> diameter;  // by density key
  double sum = 0.0;
  for (const Beam& b : scene.beams) {
    auto [it, fresh] = diameter.try_emplace(b.density.key(), 0.0);
    if (fresh) it->second = line_integral(b.density, 0.0, 2.0);
    sum += it->second * b.intensity * std::max({b.color[0], b.color[1], b.color[2]});
  }
  return sum;
}

// The same camera turned (perspective) or moved (orthographic) by (dx, dy)
// pixels: used to tell pixels where the exact image itself changes faster
// than the GPU's float rays can resolve.
Camera nudged(const Camera& cam, double dx, double dy) {
  Camera c = cam;
  const CameraBasis b = camera_basis(cam);
  const double pixel = 2.0 / cam.height;  // NDC units per pixel
  const double h = cam.projection == Projection::kOrthographic ? b.half_height : b.tan_half_fov;
  const Vec3 shift = (pixel * h) * (dx * b.right + dy * b.up);
  if (cam.projection == Projection::kOrthographic) {
    c.position = cam.position + shift;
    c.target = c.position + b.forward;
  } else {
    c.target = cam.position + b.forward + shift;
  }
  c.rotation.reset();
  c.up = b.up;
  return c;
}

// How far (in pixels) the GPU's float ray may stray from the exact one: the
// camera-relative positions, the camera's vectors and the ray direction are
// each rounded to float (2^-24 relative) and go through a few operations, so
// about 4 units in the last place, 2.4e-7 of the distance to the beam, plus
// 1e-3 pixel for the rasterizer's pixel centres.
double float_reach_px(const Scene& scene, const Camera& cam) {
  const CameraBasis b = camera_basis(cam);
  double far = 0.0;
  for (const Beam& beam : scene.beams) {
    const Vec3 p = std::holds_alternative<SphereBeam>(beam.shape)
                       ? std::get<SphereBeam>(beam.shape).center
                       : std::get<CapsuleBeam>(beam.shape).p1;
    far = std::max(far, length(p - cam.position) + beam.radius);
  }
  const double pixel = 2.0 / cam.height;
  if (cam.projection == Projection::kOrthographic) {
    return 1e-3 + 2.4e-7 * (far + b.half_height) / (pixel * b.half_height);
  }
  return 1e-3 + 2.4e-7 / (pixel * b.tan_half_fov);
}

struct Verdict {
  std::int64_t nonfinite = 0;
  std::int64_t negative = 0;
  std::int64_t edge_pixels = 0;    // errors explained by the exact image's own jump
  double rel_l1 = 0.0;             // image sum |a - r| / sum r
  double lit = 0.0;                // sum r / (pixels * scale): how much of the image is lit
  double max_over_scale = 0.0;     // max |a - r| / scale
  double max_rel_bright = 0.0;     // max |a - r| / r over pixels with r >= 0.1 scale
  double sum_signed = 0.0;         // sum (a - r): the group's bias (below) adds these up
  double sum_ref = 0.0;            // sum r
  int bad_pixel = -1;              // first pixel over the bound
  float bad_gpu = 0, bad_ref = 0;
};

// Bound on one channel of one pixel: |a - r| <= kRel r + kAbs S, with S the
// larger of the scene's energy scale (above) and the image's brightest
// reference value (rays along a capsule's axis carry far more than a
// diameter). Why these numbers: docs/accuracy.md's image L1 errors average the
// table's per-ray error away; per ray, on the sharpest densities (the thin
// shell, user tables with flanks of slope 100), the default table errs by up
// to ~3% of S at right angles, and rays at 2 .. 15 degrees to a capsule's axis
// whose s-interval still exceeds the blend band (>= 0.125) see it amplified by
// up to 1/sin(theta): measured worst 8% of S (14% of the pixel) on the shell.
// The failures the sweep exists to catch are far larger: the paper's form at
// small angles (errors of the table error times 1/sin(theta), up to 1e7),
// NaN, lost clipping, float cancellation far from the camera; with
// BEAMCAST_SWEEP_NEAR_PARALLEL=none the near-parallel group fails by the
// thousand (docs/stability.md). A pixel over the bound where the exact image
// itself changes that much within the float reach of the GPU's ray (see
// float_reach_px) is compared with the range of the reference there instead,
// and counted as an edge pixel.
constexpr double kRel = 0.10;
constexpr double kAbs = 0.05;

Verdict check_config(const Scene& scene, const Camera& cam, const HdrImage& gpu,
                     const HdrImage& ref, double beam_scale) {
  Verdict v;
  // Rays along a capsule's axis carry far more than the diameter energy: the
  // image's own brightest reference value is the scale there.
  double scale = beam_scale;
  for (float r : ref.rgb) scale = std::max(scale, static_cast<double>(r));
  double sum_err = 0.0, sum_ref = 0.0;
  std::vector<HdrImage> nudges;  // rendered only when a pixel is over the bound
  for (std::size_t i = 0; i < gpu.rgb.size(); ++i) {
    const float a = gpu.rgb[i];
    const double r = ref.rgb[i];
    if (!std::isfinite(a)) {
      ++v.nonfinite;
      continue;
    }
    if (a < 0.0f) ++v.negative;
    v.sum_signed += a - r;
    v.sum_ref += r;
    double err = std::abs(a - r);
    if (err > kRel * r + kAbs * scale) {
      if (nudges.empty()) {
        ReferenceOptions one{.threads = 1};
        const double px = float_reach_px(scene, cam);
        for (double dx : {-px, px}) {
          for (double dy : {-px, px}) {
            nudges.push_back(render_reference(scene, nudged(cam, dx, dy), one));
          }
        }
      }
      double lo = r, hi = r;
      for (const HdrImage& n : nudges) {
        lo = std::min(lo, static_cast<double>(n.rgb[i]));
        hi = std::max(hi, static_cast<double>(n.rgb[i]));
      }
      const double bracket = std::max({0.0, a - hi, lo - a});
      if (bracket <= kRel * r + kAbs * scale) {
        ++v.edge_pixels;
        err = bracket;
      } else if (v.bad_pixel < 0) {
        v.bad_pixel = static_cast<int>(i / 3);
        v.bad_gpu = a;
        v.bad_ref = static_cast<float>(r);
      }
    }
    sum_err += err;
    sum_ref += r;
    v.max_over_scale = std::max(v.max_over_scale, err / scale);
    if (r >= 0.1 * scale) v.max_rel_bright = std::max(v.max_rel_bright, err / r);
  }
  v.rel_l1 = sum_ref > 0.0 ? sum_err / sum_ref : 0.0;
  v.lit = sum_ref / (scale * static_cast<double>(gpu.rgb.size()));
  return v;
}

std::string describe(const Camera& c) {
  const CameraBasis b = camera_basis(c);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s camera at (%.17g, %.17g, %.17g) forward (%.9g, %.9g, %.9g) %s %.9g near %.3g "
                "far %.3g %dx%d",
                c.projection == Projection::kOrthographic ? "ortho" : "persp", c.position[0],
                c.position[1], c.position[2], b.forward[0], b.forward[1], b.forward[2],
                c.projection == Projection::kOrthographic ? "height" : "fov", 
                c.projection == Projection::kOrthographic ? c.ortho_height : c.fov_y_deg,
                c.near_plane, c.far_plane, c.width, c.height);
  return buf;
}

// The angle between the view direction and the first capsule's axis.
std::string axis_angle(const Scene& scene, const Camera& cam) {
  for (const Beam& b : scene.beams) {
    if (const auto* c = std::get_if<CapsuleBeam>(&b.shape)) {
      const Vec3 w = normalize(c->p1 - c->p0);
      const double s = length(cross(w, camera_basis(cam).forward));
      return ", angle to the capsule axis " + fmt("%.3g rad", std::asin(std::min(s, 1.0)));
    }
  }
  return "";
}

std::uint64_t env_u64(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 0) : fallback;
}

struct GroupStats {
  std::int64_t configs = 0;
  std::int64_t pixels = 0;
  std::int64_t lit = 0;  // configurations where at least 1% of the image's scale is lit
  std::int64_t edge_pixels = 0;
  double worst_rel_l1 = 0.0;  // over lit configurations
  double worst_max = 0.0;     // max |error| / the scene's energy scale
  double worst_rel_bright = 0.0;
  std::uint64_t worst_config = 0;
  std::int64_t failures = 0;
  double sum_signed = 0.0;  // sum over the group's pixels of (gpu - reference)
  double sum_ref = 0.0;     // sum of the reference
  void add(const Verdict& v) {
    sum_signed += v.sum_signed;
    sum_ref += v.sum_ref;
  }
  // Signed relative error of the whole group: sum (a - r) / sum r. The
  // per-pixel bound above lets every pixel be 10% off, so a uniform gain of
  // 1.04 on the GPU path would pass it; this sum would read +0.04.
  double bias() const { return sum_ref > 0.0 ? sum_signed / sum_ref : 0.0; }
};

// Bound on |GroupStats::bias()|. Measured (seed 20261122, llvmpipe), over
// 100 000 configurations: near-parallel -3.8e-5, camera on beam +2.9e-4,
// distances -1.9e-5, grazing +2.8e-3, jumps +2.4e-4, coincident -2.5e-6,
// occluders +1.4e-5, extreme cameras +1.6e-5; over the 5 000 of the ASan
// stage the largest is again grazing, +3.8e-3 (its few lit pixels sit where
// the table's error at d' -> 1 does not cancel). 1% is 2.6x the worst measured
// and a quarter of the 4% gain the per-pixel bound lets through.
constexpr double kGroupBias = 0.01;

}  // namespace

// The gap the group bias closes, on CPU images alone: per group, the
// reference of its first scenes (until some energy is in view) against itself
// times 1.04 passes every per-pixel check (4% < kRel) yet fails the group
// bias bound; times 1.0 passes both.
TEST(StabilitySweep, GroupBiasCatchesAUniformGain) {
  for (const double gain : {1.04, 1.0}) {
    for (int group = 0; group < kGroupCount; ++group) {
      GroupStats g;
      for (std::uint64_t bi = group; bi < 40 * kGroupCount && g.sum_ref <= 0.0; bi += kGroupCount) {
        const Batch b = make_batch(20261122, bi);
        for (const Camera& cam : b.draw.scene.cameras) {
          const HdrImage ref = render_reference(b.draw.scene, cam, ReferenceOptions{.threads = 1});
          HdrImage gpu = ref;
          for (float& x : gpu.rgb) x = static_cast<float>(x * gain);
          const Verdict v = check_config(b.draw.scene, cam, gpu, ref, energy_scale(b.draw.scene));
          EXPECT_EQ(v.bad_pixel, -1) << kGroupNames[group] << " gain " << gain;
          g.add(v);
        }
      }
      ASSERT_GT(g.sum_ref, 0.0) << kGroupNames[group];
      EXPECT_NEAR(g.bias(), gain - 1.0, 1e-6) << kGroupNames[group];
      EXPECT_EQ(std::abs(g.bias()) > kGroupBias, gain != 1.0) << kGroupNames[group];
    }
  }
}

// Configuration 55288 of seed 20261122: a perspective camera of fov 178.4 deg
// and near 1e-4 inside a capsule's proxy box, one pixel. Its box's faces are
// clipped behind the eye and NVIDIA's rasterizer dropped the one sample (GPU
// 0 against the reference's 0.3076); llvmpipe covered it. The beam takes
// the full-screen path now (beam_proxy_full_screen), on every driver.
TEST(StabilitySweep, Configuration55288EyeInsideProxyAtExtremeFov) {
  constexpr std::uint64_t kConfig = 55288;
  const Batch b = make_batch(20261122, kConfig / kCamerasPerScene);
  const Camera& cam = b.draw.scene.cameras[kConfig % kCamerasPerScene];
  ASSERT_EQ(cam.width, 1);
  ASSERT_GT(cam.fov_y_deg, 178.0);
  const CameraBasis basis = camera_basis(cam);
  int full_screen = 0;
  for (const Beam& beam : b.draw.scene.beams) {
    const BeamGpu g = std::visit([&](const auto& shape) { return shape.gpu(basis.eye); }, beam.shape);
    full_screen += beam_proxy_full_screen(g, beam.radius, cam, basis) ? 1 : 0;
  }
  EXPECT_GE(full_screen, 1) << "the eye is inside a proxy box: that beam must be full-screen";
  static Renderer renderer;
  const std::vector<FrameResult> frames =
      renderer.render(b.draw.scene, {cam}, FrameOptions{.read_hdr = true});
  const HdrImage ref = render_reference(b.draw.scene, cam, ReferenceOptions{.threads = 1});
  ASSERT_GT(ref.rgb[0] + ref.rgb[1] + ref.rgb[2], 0.0f);
  const Verdict v = check_config(b.draw.scene, cam, frames[0].hdr, ref, energy_scale(b.draw.scene));
  EXPECT_EQ(v.nonfinite, 0);
  EXPECT_EQ(v.bad_pixel, -1) << "gpu " << v.bad_gpu << " reference " << v.bad_ref;
}

TEST(StabilitySweep, RandomConfigurations) {
  const std::uint64_t seed = env_u64("BEAMCAST_SWEEP_SEED", 20261122);
  const std::uint64_t size = env_u64("BEAMCAST_SWEEP_SIZE", 100000);
  const std::uint64_t first = env_u64("BEAMCAST_SWEEP_FIRST", 0);
  const std::uint64_t batches = (size + kCamerasPerScene - 1) / kCamerasPerScene;
  // BEAMCAST_SWEEP_NEAR_PARALLEL=none renders with the paper's form (to show
  // that the bound catches its streaks; docs/stability.md).
  // BEAMCAST_SWEEP_GROUP=<n> keeps only group n (0 .. 7, the table's order).
  const int only_group =
      std::getenv("BEAMCAST_SWEEP_GROUP") ? static_cast<int>(env_u64("BEAMCAST_SWEEP_GROUP", 0)) : -1;
  const char* np = std::getenv("BEAMCAST_SWEEP_NEAR_PARALLEL");
  const NearParallel near_parallel = np != nullptr && std::string(np) == "none"
                                         ? NearParallel::kNone
                                         : NearParallel::kQuadrature;
  const std::uint64_t first_batch = first / kCamerasPerScene;
  const char* gain_env = std::getenv("BEAMCAST_SWEEP_GPU_GAIN");
  const double gain = gain_env ? std::strtod(gain_env, nullptr) : 1.0;
  std::printf("sweep: seed %" PRIu64 ", size %" PRIu64 " configurations (%" PRIu64
              " scenes x %d cameras) from configuration %" PRIu64
              "; replay with BEAMCAST_SWEEP_SEED / BEAMCAST_SWEEP_SIZE / BEAMCAST_SWEEP_FIRST\n",
              seed, batches * kCamerasPerScene, batches, kCamerasPerScene,
              first_batch * kCamerasPerScene);
  const auto t0 = std::chrono::steady_clock::now();

  static Renderer renderer;
  std::vector<GroupStats> stats(kGroupCount);
  std::int64_t nonfinite = 0, negative = 0, failures = 0, pixels = 0;
  double wait_s = 0.0;
  // Chunks of scenes: the references of a chunk are computed on a second
  // thread while this one renders the chunk on the GPU (llvmpipe).
  constexpr std::uint64_t kChunk = 32;
  for (std::uint64_t c0 = first_batch; c0 < first_batch + batches; c0 += kChunk) {
    const std::uint64_t c1 = std::min(c0 + kChunk, first_batch + batches);
    std::vector<Batch> chunk;
    for (std::uint64_t bi = c0; bi < c1; ++bi) {
      if (only_group >= 0 && static_cast<int>(bi % kGroupCount) != only_group) continue;
      chunk.push_back(make_batch(seed, bi));
      chunk.back().draw.scene.render.near_parallel = near_parallel;
    }
    std::vector<double> scales;
    for (const Batch& b : chunk) scales.push_back(energy_scale(b.draw.scene));
    std::vector<std::vector<HdrImage>> refs(chunk.size());
    std::thread reference([&] {
      for (std::size_t i = 0; i < chunk.size(); ++i) {
        for (const Camera& cam : chunk[i].draw.scene.cameras) {
          refs[i].push_back(render_reference(chunk[i].draw.scene, cam, ReferenceOptions{.threads = 1}));
        }
      }
    });
    std::vector<std::vector<FrameResult>> frames;
    for (const Batch& b : chunk) {
      frames.push_back(renderer.render(b.draw.scene, FrameOptions{.read_hdr = true}));
      // Test-only: BEAMCAST_SWEEP_GPU_GAIN=1.04 shows the group bias bound fail.
      if (gain != 1.0) {
        for (FrameResult& f : frames.back()) {
          for (float& x : f.hdr.rgb) x = static_cast<float>(x * gain);
        }
      }
    }
    const auto j0 = std::chrono::steady_clock::now();
    reference.join();
    wait_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - j0).count();
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      const Batch& b = chunk[i];
      GroupStats& g = stats[b.group];
      for (int k = 0; k < kCamerasPerScene; ++k) {
        const Camera& cam = b.draw.scene.cameras[k];
        const Verdict v = check_config(b.draw.scene, cam, frames[i][k].hdr, refs[i][k], scales[i]);
        const std::uint64_t config = b.index * kCamerasPerScene + k;
        ++g.configs;
        g.pixels += static_cast<std::int64_t>(cam.width) * cam.height;
        pixels += static_cast<std::int64_t>(cam.width) * cam.height;
        g.edge_pixels += v.edge_pixels;
        g.add(v);
        nonfinite += v.nonfinite;
        negative += v.negative;
        if (v.lit >= 1e-2) {
          ++g.lit;
          g.worst_rel_l1 = std::max(g.worst_rel_l1, v.rel_l1);
        }
        if (v.max_over_scale > g.worst_max) {
          g.worst_max = v.max_over_scale;
          g.worst_config = config;
        }
        g.worst_rel_bright = std::max(g.worst_rel_bright, v.max_rel_bright);
        if (v.nonfinite > 0 || v.negative > 0 || v.bad_pixel >= 0) {
          ++failures;
          ++g.failures;
          if (std::getenv("BEAMCAST_SWEEP_VERBOSE")) {
            const HdrImage& a = frames[i][k].hdr;
            const HdrImage& r = refs[i][k];
            for (int p = 0; p < a.width * a.height; ++p) {
              std::printf("  pixel %2d (%d, %d): gpu %.6g  reference %.6g\n", p, p % a.width,
                          p / a.width, a.rgb[3 * p], r.rgb[3 * p]);
            }
          }
          if (failures <= 60) {
            ADD_FAILURE() << "configuration " << config << " (seed " << seed << "): "
                          << kGroupNames[b.group] << ", " << b.draw.what << ", scale " << b.scale
                          << ", offset " << b.offset << ", " << describe(cam) << ": nonfinite "
                          << v.nonfinite << ", negative " << v.negative << ", pixel "
                          << v.bad_pixel << " gpu " << v.bad_gpu << " reference " << v.bad_ref
                          << " (energy scale " << scales[i] << ")" << axis_angle(b.draw.scene, cam);
          }
        }
      }
    }
  }
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("sweep: %-44s %7s %8s %6s %10s %10s %10s %6s %5s %9s\n", "group", "configs",
              "pixels", "lit", "rel_l1", "max/scale", "rel>=0.1", "edge", "fail", "bias");
  std::int64_t configs = 0;
  for (int gi = 0; gi < kGroupCount; ++gi) {
    const GroupStats& g = stats[gi];
    configs += g.configs;
    std::printf("sweep: %-44s %7lld %8lld %6lld %10.2e %10.2e %10.2e %6lld %5lld %+9.2e  (worst: configuration %" PRIu64 ")\n",
                kGroupNames[gi], static_cast<long long>(g.configs), static_cast<long long>(g.pixels),
                static_cast<long long>(g.lit), g.worst_rel_l1, g.worst_max, g.worst_rel_bright,
                static_cast<long long>(g.edge_pixels), static_cast<long long>(g.failures), g.bias(),
                g.worst_config);
    EXPECT_LE(std::abs(g.bias()), kGroupBias)
        << kGroupNames[gi] << ": the GPU path's summed energy is off by " << g.bias()
        << " of the reference's over the group";
  }
  std::printf("sweep: %" PRIu64 " configurations, %lld pixels, %lld NaN/Inf values, %lld negative, "
              "%lld over the bound, %.1f s (seed %" PRIu64 ")\n",
              static_cast<std::uint64_t>(configs), static_cast<long long>(pixels),
              static_cast<long long>(nonfinite), static_cast<long long>(negative),
              static_cast<long long>(failures), secs, seed);
  std::printf("sweep: %.1f s of it waiting for the reference thread\n", wait_s);
  EXPECT_EQ(nonfinite, 0);
  EXPECT_EQ(negative, 0);
  EXPECT_EQ(failures, 0);
}

}  // namespace beamcast
