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
#include <filesystem>
#include <functional>
#include <numbers>
#include <string>

#include "protocol/camera.hpp"
#include "protocol/scene_json.hpp"
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

// The must-show of issue 5: through-energy of capsules seen at angle theta to
// their axis, orthographic (every pixel has that angle), outside and inside,
// at the default table, with the paper's form ([g(s1) - g(s0)] / sin(theta)
// at every angle, near_parallel = "none") and with ours. Ours must stay within
// 1% relative L1 at every angle down to 1e-7 rad (and 0); the paper's form
// must exceed that somewhere below 1e-2 rad, or the near-parallel path would
// be unneeded. BEAMCAST_DOC_IMAGES=<dir> also writes the streak pictures of
// docs/stability.md there.
TEST(Stability, NearParallelThroughEnergyPaperVersusOurs) {
  const double angles[] = {std::numbers::pi / 2, 0.3, 0.1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4,
                           1e-5, 1e-6, 1e-7, 0.0};
  double paper_worst_small = 0.0;
  std::printf("stability angle table: theta [rad] | paper rel_l1 (worst case) | ours rel_l1 (worst case)\n");
  for (double theta : angles) {
    double worst[2] = {0.0, 0.0};
    std::string where[2];
    for (const char* density : {"linear", "abe", "gaussian", "shell"}) {
      for (double back : {8.0, 0.5}) {
        const Vec3 dir{std::sin(theta), 0.0, -std::cos(theta)};
        Scene s = with({capsule({0, 0, -5}, {0, 0, 5}, 1.0, density)},
                       parallel_camera(theta, Vec3{0.2, 0.1, 0.0} - back * dir));
        const HdrImage ref = render_reference(s, s.cameras[0]);
        for (int mode = 0; mode < 2; ++mode) {
          s.render.near_parallel = mode == 0 ? NearParallel::kNone : NearParallel::kQuadrature;
          const auto frames = renderer().render(s, FrameOptions{.read_hdr = true});
          const HdrError e = compare_hdr(frames[0].hdr, ref);
          // The paper's form divides by sin(theta) = 0 at theta = 0: count Inf/NaN as 100%.
          const double err = e.nonfinite > 0 ? 1.0 : e.rel_l1;
          if (err > worst[mode]) {
            worst[mode] = err;
            where[mode] = std::string(density) + (back > 1 ? " outside" : " inside");
          }
        }
      }
    }
    std::printf("stability angle table: %8.1e | %9.2e (%-16s) | %9.2e (%s)\n", theta, worst[0],
                where[0].c_str(), worst[1], where[1].c_str());
    EXPECT_LE(worst[1], 1e-2) << "theta " << theta;
    if (theta <= 1e-2) paper_worst_small = std::max(paper_worst_small, worst[0]);
  }
  EXPECT_GT(paper_worst_small, 1e-2) << "the paper's form stays within 1%: the near-parallel path is unneeded";

  const char* dir = std::getenv("BEAMCAST_DOC_IMAGES");
  if (dir == nullptr) return;
  // The paper's fig 3.4: looking nearly along a capsule's axis, here at 1e-4
  // rad for every pixel (orthographic), from outside through the end cap; the
  // shell density shows the streaks first.
  const double theta = 1e-4;
  Camera cam = parallel_camera(theta, Vec3{0.0, 0.0, 0.0} - 8.0 * Vec3{std::sin(theta), 0.0, -std::cos(theta)});
  cam.width = cam.height = 256;
  cam.ortho_height = 2.4;
  Scene s = with({capsule({0, 0, -5}, {0, 0, 5}, 1.0, "shell")}, cam);
  s.output.exposure = 0.02;
  const HdrImage ref = render_reference(s, cam);
  write_png(std::filesystem::path(dir) / "streak_reference.png", tone_map(ref, s.output));
  for (int mode = 0; mode < 2; ++mode) {
    s.render.near_parallel = mode == 0 ? NearParallel::kNone : NearParallel::kQuadrature;
    const auto frames = renderer().render(s, FrameOptions{.read_hdr = true});
    const std::string name = mode == 0 ? "streak_paper" : "streak_ours";
    write_png(std::filesystem::path(dir) / (name + ".png"), frames[0].image);
    // |error| amplified 50x on the same tone curve, so both error pictures share a scale.
    HdrImage err = ref;
    for (std::size_t i = 0; i < err.rgb.size(); ++i) {
      err.rgb[i] = 50.0f * std::abs(frames[0].hdr.rgb[i] - ref.rgb[i]);
    }
    write_png(std::filesystem::path(dir) / (name + "_error50x.png"), tone_map(err, s.output));
    const HdrError e = compare_hdr(frames[0].hdr, ref);
    std::printf("stability streak picture %s: rel_l1 %.2e max_abs %.3g\n", name.c_str(), e.rel_l1,
                e.max_abs);
  }
}

// The shortest capsule validation accepts: |p1 - p0| just above 1e-9 *
// max(1, r) (scene_json refuses shorter ones as degenerate_capsule). Its axis
// direction is computed from a difference of ~1e-9, so the GPU's float axis may
// point anywhere; the pieces must still add up to (nearly) a sphere.
TEST(Stability, ShortestAcceptedCapsule) {
  for (double r : {1e-3, 1.0, 1e3}) {
    const double len = 1.0001e-9 * std::max(1.0, r);
    const Vec3 p0{0.1 * r, -0.2 * r, 0.3 * r};
    const Vec3 p1 = p0 + len * normalize(Vec3{1, 2, 3});
    // Through the parser: the scene is valid (just above the threshold).
    const nlohmann::json j = {
        {"beams",
         {{{"type", "capsule"}, {"p0", p0}, {"p1", p1}, {"radius", r}, {"density", {{"type", "abe"}}}}}},
        {"cameras", {{{"position", {0.5 * r, 0.4 * r, 3.0 * r}}, {"target", p0}, {"fov_y", 50},
                      {"near", 1e-3 * r}, {"far", 1e3 * r}, {"width", 48}, {"height", 48}}}}};
    Scene s = parse_scene(j, {});
    check("shortest capsule r=" + std::to_string(r), s);
    // One texel of the table is 1/128 of a radius; 1e-9 of a radius changes
    // nothing a float can hold, so the capsule renders as its sphere does
    // (the same bound as against the reference).
    Scene as_sphere = s;
    as_sphere.beams[0].shape = SphereBeam{p0};
    const auto a = renderer().render(s, FrameOptions{.read_hdr = true});
    const auto b = renderer().render(as_sphere, FrameOptions{.read_hdr = true});
    const HdrError e = compare_hdr(a[0].hdr, b[0].hdr);
    std::printf("stability %-40s rel_l1 %.2e against its sphere\n",
                ("shortest capsule r=" + std::to_string(r)).c_str(), e.rel_l1);
    EXPECT_LE(e.rel_l1, 5e-3);
  }
}

// Continuity across a capsule's end plane, where the cylinder piece hands over
// to the cap's half sphere: along each scanline, no jump between neighbouring
// pixels may exceed the reference's own jump there by more than the tolerance.
// Scanlines cross the end plane's image at several view angles (angle between
// the view and the axis) and several roll angles (the scanline's direction).
//
// Tolerance 4e-3 of the image's brightest reference value. Away from a seam
// the excess is the difference of two neighbouring rays' errors. Measured
// (llvmpipe), from 90 down to 10 degrees: linear and abe <= 8e-4, gaussian
// <= 1.5e-3 (its cut at x = 1 at the silhouette), shell <= 1.8e-3; at 2
// degrees the rays' s-intervals fall in the band where the table and the
// quadrature are blended and the table's error is amplified by 1/sin(theta)
// ~ 29, and abe's and the shell's neighbouring errors differ by up to 2.5e-3
// (inside the image of the body, not at the end plane). 4e-3 leaves 1.6x
// margin on that. A seam, the cylinder and the cap disagreeing along the end
// plane, is a step that does not shrink with the pixel size; the test checks
// itself by adding a 1% step beyond the end plane to the GPU image and
// requiring that to fail.
// Largest |jump of img| - |jump of ref| between horizontal neighbours, over
// the pairs where `near_end` holds for either pixel, relative to ref_max.
double excess_jump(const HdrImage& img, const HdrImage& ref, double ref_max,
                   const std::vector<bool>& near_end, int* at = nullptr) {
  double worst = 0.0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x + 1 < img.width; ++x) {
      if (!near_end[y * img.width + x] && !near_end[y * img.width + x + 1]) continue;
      for (int k = 0; k < 3; ++k) {
        const double ja = std::abs(img.at(x + 1, y)[k] - img.at(x, y)[k]);
        const double jr = std::abs(ref.at(x + 1, y)[k] - ref.at(x, y)[k]);
        if ((ja - jr) / ref_max > worst) {
          worst = (ja - jr) / ref_max;
          if (at) *at = y * img.width + x;
        }
      }
    }
  }
  return worst;
}

TEST(Stability, ContinuousAcrossTheEndPlane) {
  constexpr double kTolerance = 4e-3;
  const Vec3 w{1, 0, 0};
  const Vec3 end{2, 0, 0};  // p1: the end plane x = 2
  int cases = 0;
  for (const char* density : {"linear", "abe", "gaussian", "shell"}) {
    for (double phi_deg : {90.0, 60.0, 30.0, 10.0, 2.0}) {
      for (double roll_deg : {0.0, 35.0, 70.0}) {
        const double phi = phi_deg * std::numbers::pi / 180, roll = roll_deg * std::numbers::pi / 180;
        const Vec3 v{std::cos(phi), 0.0, -std::sin(phi)};  // angle phi to the axis
        const Vec3 side{0, 1, 0};
        Camera cam;
        cam.projection = Projection::kOrthographic;
        cam.position = end - 10.0 * v;
        cam.target = end;
        // Rolled so the scanlines (image rows) cross the end plane's image
        // obliquely.
        cam.up = std::cos(roll) * side + std::sin(roll) * cross(v, side);
        cam.ortho_height = 2.6;
        cam.width = 128;
        cam.height = 32;
        cam.near_plane = 1e-3;
        cam.far_plane = 100;
        Scene s = with({capsule({-2, 0, 0}, end, 1.0, density)}, cam);
        const auto frames = renderer().render(s, FrameOptions{.read_hdr = true});
        const HdrImage ref = render_reference(s, cam);
        double ref_max = 0.0;
        for (float v2 : ref.rgb) ref_max = std::max(ref_max, static_cast<double>(v2));
        ASSERT_GT(ref_max, 0.0);
        // The pixels whose rays pass within 1.5 radii of the end point: the
        // end plane's crossing with the body and its surroundings. `beyond`:
        // the ray's closest approach to the end point lies past the plane.
        const CameraBasis basis = camera_basis(cam);
        std::vector<bool> near_end(cam.width * cam.height), beyond(cam.width * cam.height);
        for (int y = 0; y < cam.height; ++y) {
          for (int x = 0; x < cam.width; ++x) {
            const Ray ray = camera_ray(cam, basis, x, cam.height - 1 - y);
            const Vec3 q = ray.origin + dot(end - ray.origin, ray.dir) * ray.dir;
            near_end[y * cam.width + x] = length(q - end) <= 1.5;
            beyond[y * cam.width + x] = dot(q - end, w) > 0.0;
          }
        }
        int at = -1;
        const double excess = excess_jump(frames[0].hdr, ref, ref_max, near_end, &at);
        std::printf("stability end plane %-9s view %4.0f deg roll %3.0f deg: excess jump %.2e of the peak\n",
                    density, phi_deg, roll_deg, excess);
        EXPECT_LE(excess, kTolerance) << density << " phi " << phi_deg << " roll " << roll_deg
                                      << ": worst pair at pixel (" << at % cam.width << ", "
                                      << at / cam.width << ")";
        // The check can fail: a 1% step where the rays enter the cap region.
        HdrImage seam = frames[0].hdr;
        for (int y = 0; y < seam.height; ++y) {
          for (int x = 0; x < seam.width; ++x) {
            if (!beyond[y * cam.width + x]) continue;
            for (int k = 0; k < 3; ++k) seam.at(x, y)[k] += static_cast<float>(1e-2 * ref_max);
          }
        }
        EXPECT_GT(excess_jump(seam, ref, ref_max, near_end), kTolerance)
            << "the seam check cannot fail";
        ++cases;
      }
    }
  }
  std::printf("stability end plane: %d cases\n", cases);
}

}  // namespace
}  // namespace beamcast
