// Hard cases (issue 5): each rendered on the GPU path and by the CPU reference
// in double; no NaN or Inf, no negative energy, and the image error within a
// stated bound. Prints one line per case with its worst error.
//
// Bound: relative L1 on HDR <= 5e-3 and max |error| <= 5% of the reference's
// brightest value. The default table's own interpolation error on these
// densities is <= 3e-4 (docs/accuracy.md); 5e-3 leaves room for the cases'
// float-precision losses (far cameras, tiny and huge radii) that the suite is
// here to bound, while a streak (the paper's fig 3.4: whole rows of pixels
// off by the table error times 1/sin(theta)) or a NaN fails it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "protocol/camera.hpp"
#include "render/image.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"
#include "tests/unit/test_densities.hpp"

namespace beamcast {
namespace {

Renderer& renderer() {
  static Renderer r;
  return r;
}

using testing_support::named;

Beam capsule(Vec3 p0, Vec3 p1, double r, const char* density = "linear", bool caps = true) {
  Beam b;
  b.shape = CapsuleBeam{p0, p1, caps, caps};
  b.radius = r;
  b.density = named(density);
  return b;
}

Beam sphere(Vec3 c, double r, const char* density = "linear") {
  Beam b;
  b.shape = SphereBeam{c};
  b.radius = r;
  b.density = named(density);
  return b;
}

Camera look(Vec3 pos, Vec3 target, double fov = 40.0, int size = 48) {
  Camera c;
  c.position = pos;
  c.target = target;
  c.fov_y_deg = fov;
  c.width = c.height = size;
  c.near_plane = 1e-3;
  c.far_plane = 1e4;
  // An up vector never parallel to the view direction.
  const Vec3 f = normalize(target - pos);
  c.up = std::abs(f[1]) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  return c;
}

struct Result {
  HdrError err;
  double ref_max = 0.0;
  double min_value = 0.0;
};

Result run(const Scene& scene) {
  Result r;
  const auto frames = renderer().render(scene, FrameOptions{.read_hdr = true});
  const HdrImage ref = render_reference(scene, scene.cameras[0]);
  r.err = compare_hdr(frames[0].hdr, ref);
  for (float v : ref.rgb) r.ref_max = std::max(r.ref_max, static_cast<double>(v));
  r.min_value = *std::min_element(frames[0].hdr.rgb.begin(), frames[0].hdr.rgb.end());
  return r;
}

void check(const std::string& name, const Scene& scene, double rel_bound = 5e-3) {
  const Result r = run(scene);
  const double rel_max = r.ref_max > 0.0 ? r.err.max_abs / r.ref_max : r.err.max_abs;
  std::printf("stability %-40s rel_l1 %.2e  max_abs/ref_max %.2e  ref_max %.2e  nonfinite %lld\n",
              name.c_str(), r.err.rel_l1, rel_max, r.ref_max,
              static_cast<long long>(r.err.nonfinite));
  // A case that renders nothing tests nothing.
  EXPECT_GT(r.ref_max, 0.0) << name << ": the camera sees no beam";
  EXPECT_EQ(r.err.nonfinite, 0) << name;
  EXPECT_GE(r.min_value, 0.0f) << name;
  EXPECT_LE(r.err.rel_l1, rel_bound) << name;
  EXPECT_LE(rel_max, 0.05) << name;
}

Scene with(std::vector<Beam> beams, Camera cam) {
  Scene s;
  s.beams = std::move(beams);
  s.cameras = {cam};
  return s;
}

// View direction at angle theta from the capsule's axis (-z), orthographic so
// that every pixel's ray has exactly that angle.
Camera parallel_camera(double theta, Vec3 pos) {
  Camera c;
  c.projection = Projection::kOrthographic;
  c.position = pos;
  c.rotation = std::array<double, 4>{std::cos(theta / 2), 0.0, std::sin(-theta / 2), 0.0};
  c.ortho_height = 3.0;
  c.width = c.height = 48;
  c.near_plane = 1e-4;
  c.far_plane = 1e3;
  return c;
}

TEST(Stability, RaysParallelToACapsuleAxis) {
  for (double theta : {std::numbers::pi / 2, 0.2, 1e-2, 1e-3, 1e-5, 1e-7, 0.0}) {
    for (const char* density : {"linear", "shell"}) {
      const std::string tag = std::string(density) + " theta=" + std::to_string(theta);
      // Looking at (0.2, 0.1, 0), near the capsule's middle, from 8 units away
      // (outside; through the end cap when theta is small) and from 0.5 units
      // (inside the capsule).
      const Vec3 dir{std::sin(theta), 0.0, -std::cos(theta)};
      const Vec3 aim{0.2, 0.1, 0.0};
      check("parallel outside " + tag,
            with({capsule({0, 0, -5}, {0, 0, 5}, 1.0, density)},
                 parallel_camera(theta, aim - 8.0 * dir)));
      check("parallel inside " + tag,
            with({capsule({0, 0, -5}, {0, 0, 5}, 1.0, density)},
                 parallel_camera(theta, aim - 0.5 * dir)));
    }
  }
}

TEST(Stability, CameraInsideOrOnABeam) {
  check("camera at sphere centre", with({sphere({0, 0, 0}, 1.0)}, look({0, 0, 0}, {0, 0, -1}, 90)));
  check("camera on sphere surface", with({sphere({0, 0, 0}, 1.0)}, look({0, 0, 1}, {0, 0, 0}, 90)));
  check("camera on capsule axis, along",
        with({capsule({0, 0, -3}, {0, 0, 3}, 1.0)}, look({0, 0, 0}, {0, 0, -1}, 90)));
  check("camera on capsule axis, across",
        with({capsule({0, 0, -3}, {0, 0, 3}, 1.0)}, look({0, 0, 0}, {1, 0, 0}, 90)));
  check("camera on end plane",
        with({capsule({0, 0, -3}, {0, 0, 3}, 1.0)}, look({0.5, 0, 3}, {0, 0, 0}, 90)));
}

TEST(Stability, RadiiAndDistancesAcrossScales) {
  for (double s : {1e-6, 1e-3, 1.0, 1e3, 1e6}) {
    Camera cam = look({0.3 * s, 0.4 * s, 6 * s}, {0, 0, 0});
    cam.near_plane = 1e-3 * s;
    cam.far_plane = 1e3 * s;
    check("scale " + std::to_string(s),
          with({sphere({0, 0, 0}, s), capsule({0, 0, 0}, {2 * s, s, 0}, 0.4 * s)}, cam));
  }
  for (double d : {1e-3, 1e-1, 10.0, 1e3, 1e6}) {
    // Sphere of radius 1 filling about half the view from distance d + 1.
    Camera cam = look({0, 0, 1 + d}, {0, 0, 0}, 2 * std::atan(2.0 / (1 + d)) * 180 / std::numbers::pi);
    cam.near_plane = 1e-4;
    cam.far_plane = 10 * (1 + d);
    check("camera distance " + std::to_string(d), with({sphere({0, 0, 0}, 1.0, "abe")}, cam));
  }
  const Vec3 far{1e5, -1e5, 1e5};
  check("beams 1e5 from the origin",
        with({sphere(far, 1.0), capsule(far, far + Vec3{2, 1, 0}, 0.4)},
             look(far + Vec3{0.3, 0.4, 6}, far)));
}

TEST(Stability, DensitiesWithJumpsSpikesAndCores) {
  Density step;
  step.kind = DensityKind::kTable;
  step.samples = {1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0};
  Beam stepped = sphere({0, 0, 0}, 1.0);
  stepped.density = step;
  check("user table with a step", with({stepped}, look({0, 0, 3}, {0, 0, 0})));
  check("thin shell", with({sphere({0, 0, 0}, 1.0, "shell")}, look({0, 0, 3}, {0, 0, 0})));
  check("abe core, ray through the centre",
        with({sphere({0, 0, 0}, 1.0, "abe")}, look({0, 0, 3}, {0, 0, 0}, 0.5)));
  check("grazing the boundary d' -> 1",
        with({sphere({0, 0, 0}, 1.0, "gaussian")}, look({0.99, 0, 3}, {0.99, 0, 0}, 0.5)));
}

TEST(Stability, ManyAndCoincidentBeams) {
  check("coincident beams",
        with({capsule({0, 0, 0}, {1, 0, 0}, 0.5), capsule({0, 0, 0}, {1, 0, 0}, 0.5)},
             look({0.5, 0.5, 3}, {0.5, 0, 0})));
  std::vector<Beam> many;
  for (int i = 0; i < 1000; ++i) many.push_back(sphere({0.001 * (i % 10), 0, 0}, 1.0, "quadratic"));
  check("1000 overlapping beams", with(many, look({0, 0, 4}, {0, 0, 0})));
}

Occluder plane_at(Vec3 point, Vec3 normal) {
  Occluder o;
  o.shape = PlaneOccluder{point, normal};
  return o;
}

Occluder ball_at(Vec3 center, double radius) {
  Occluder o;
  o.shape = SphereOccluder{center, radius};
  return o;
}

TEST(Stability, OccludersInsideBeams) {
  const std::vector<Beam> beams = {sphere({0, 0, 0}, 1.0, "abe"),
                                   capsule({0, 0, 0}, {2, 0.5, 0}, 0.5, "shell")};
  const Camera cam = look({0.6, 0.8, 4}, {0.6, 0, 0});
  Scene s = with(beams, cam);
  s.occluders = {plane_at({0, 0, 0}, {0, 0, 1})};  // through the sphere's centre
  check("plane through a beam's centre", s);
  s.occluders = {ball_at({0, 0, 0}, 0.2)};  // around the centre, inside the beam
  check("occluder around the centre", s);
  s.occluders = {ball_at({1.2, 0.3, 0.0}, 0.15)};  // inside the capsule (radius 0.5)
  check("occluder inside a capsule", s);
  // A plane through the camera itself lies before the near plane: clipped away,
  // it hides nothing, and both renderers must agree on that.
  s.occluders = {plane_at(cam.position, {0, 0, 1})};
  check("occluder at the camera", s);
  // Behind the far plane: it must change nothing.
  Scene far = with(beams, cam);
  far.cameras[0].far_plane = 20;
  far.occluders = {plane_at({0, 0, -30}, {0, 0, 1})};
  check("occluder behind the far plane", far);
}

TEST(Stability, ExtremeCameras) {
  const std::vector<Beam> beams = {sphere({0, 0, 0}, 1.0, "abe"), capsule({0, 0, 0}, {2, 1, 0}, 0.4)};
  check("fov 0.01 deg", with(beams, look({0.5, 0.2, 5}, {0.5, 0.2, 0}, 0.01)));
  // Inside the abe sphere: at 179 degrees anything farther covers no pixel centre.
  check("fov 179 deg", with(beams, look({0.2, 0.1, 0.3}, {0.2, 0.1, -1}, 179)));
  Camera ortho = look({0.5, 0.2, 5}, {0.5, 0.2, 0});
  ortho.projection = Projection::kOrthographic;
  ortho.ortho_height = 4;
  check("orthographic", with(beams, ortho));
  Camera tiny_near = look({0.5, 0.2, 5}, {0.5, 0.2, 0});
  tiny_near.near_plane = 1e-6;
  tiny_near.far_plane = 1e9;
  check("near 1e-6, far 1e9", with(beams, tiny_near));
  Camera one = look({0.3, 0.1, 5}, {0, 0, 0});
  one.width = one.height = 1;
  check("1x1 image", with(beams, one));
}

}  // namespace
}  // namespace beamcast
