#include "bench/bench_scenes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "protocol/camera.hpp"
#include "protocol/check.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast::bench {
namespace {

Density builtin(const char* name) {
  Density d;
  BEAMCAST_CHECK(density_from_name(name, &d), std::string("no density ") + name);
  return d;
}

Camera look_at(const Vec3& position, const Vec3& target, double fov_y_deg, int size) {
  Camera cam;
  cam.name = "view";
  cam.position = position;
  cam.target = target;
  cam.fov_y_deg = fov_y_deg;
  cam.width = size;
  cam.height = size;
  return cam;
}

Beam sphere(const Vec3& c, double radius, const Density& d, const Color& color) {
  Beam b;
  b.shape = SphereBeam{c};
  b.radius = radius;
  b.density = d;
  b.color = color;
  return b;
}

Beam capsule(const Vec3& p0, const Vec3& p1, double radius, const Density& d, const Color& color) {
  Beam b;
  b.shape = CapsuleBeam{p0, p1, true, true};
  b.radius = radius;
  b.density = d;
  b.color = color;
  return b;
}

// The benchmark's invariants, whatever the source of the scene.
BenchScene finish(std::string name, Scene scene, int size) {
  if (scene.cameras.empty()) throw std::runtime_error(name + ": scene has no camera");
  scene.background = {0.0, 0.0, 0.0};
  scene.occluders.clear();
  scene.cameras.resize(1);
  scene.cameras[0].width = size;
  scene.cameras[0].height = size;
  scene.render = RenderSettings{};
  BenchScene bs;
  bs.name = std::move(name);
  bs.closed_form = std::all_of(scene.beams.begin(), scene.beams.end(),
                               [](const Beam& b) { return has_closed_form(b.density); });
  bs.scene = std::move(scene);
  return bs;
}

BenchScene from_example(const std::filesystem::path& dir, const std::string& name, int size) {
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  return finish(name, load_scene_file(dir / (name + ".json"), opts), size);
}

// A long linear-density capsule seen from outside, 2 degrees off its axis:
// the rays through its middle are nearly parallel to the axis, where the
// table's s-interval shrinks while the 1/sin(theta) factor grows.
BenchScene grazing_capsule(int size) {
  Scene s;
  s.beams.push_back(capsule({0.0, 0.0, -5.0}, {0.0, 0.0, 5.0}, 0.5, builtin("linear"),
                            {1.0, 0.75, 0.4}));
  const double off_axis = 2.0 * std::numbers::pi / 180.0;
  const double dist = 14.0;
  s.cameras.push_back(look_at({dist * std::sin(off_axis), 0.0, dist * std::cos(off_axis)},
                              {0.0, 0.0, 0.0}, 12.0, size));
  // Energy along the axis reaches ~20 (10 units of length / r = 0.5): keep the
  // tone curve off its shoulder so the 8-bit PSNR still sees the error.
  s.output.exposure = 0.12;
  return finish("grazing_capsule", std::move(s), size);
}

// A sphere and a capsule crossing it, both of one density, seen obliquely so
// the capsule's obliquity factor varies over the picture.
BenchScene density_scene(const char* density, int size) {
  Scene s;
  const Density d = builtin(density);
  s.beams.push_back(sphere({-0.6, 0.2, 0.0}, 1.0, d, {0.4, 0.8, 1.0}));
  s.beams.push_back(capsule({-2.0, -1.0, -0.5}, {2.2, 0.9, 0.6}, 0.45, d, {1.0, 0.5, 0.3}));
  s.cameras.push_back(look_at({0.5, 1.5, 6.5}, {0.0, 0.0, 0.0}, 50.0, size));
  // The shell's peak density is 5 against ~1 for the others.
  s.output.exposure = std::string(density) == "shell" ? 0.5 : 0.8;
  BenchScene bs = finish(std::string("density_") + density, std::move(s), size);
  bs.density_study = true;
  return bs;
}

// `count` random spheres and capsules in a cube whose side grows as the cube
// root of the count, so the density of overlaps stays about the same. Only
// densities with a closed form are drawn, so every method (closed_form
// included) gets a row; the shell is covered by thin_shell and density_shell.
BenchScene random_beams(int count, std::uint32_t seed, int size) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const char* const kDensities[] = {"abe", "linear", "quadratic", "gaussian"};
  const double half = 0.9 * std::cbrt(static_cast<double>(count));
  Scene s;
  for (int i = 0; i < count; ++i) {
    const Density d = builtin(kDensities[rng() % 4]);
    const Vec3 c{uniform(-half, half), uniform(-half, half), uniform(-half, half)};
    const Color color{uniform(0.3, 1.0), uniform(0.3, 1.0), uniform(0.3, 1.0)};
    const double radius = uniform(0.25, 0.7);
    Beam b;
    if (unit(rng) < 0.5) {
      b = sphere(c, radius, d, color);
    } else {
      // Random axis direction (normalized Gaussian vector is uniform on the sphere).
      std::normal_distribution<double> gauss;
      const Vec3 axis = normalize({gauss(rng), gauss(rng), gauss(rng)});
      const double len = uniform(0.5, 4.0);
      b = capsule(c - (0.5 * len) * axis, c + (0.5 * len) * axis, radius, d, color);
    }
    b.intensity = uniform(0.3, 1.0);
    s.beams.push_back(std::move(b));
  }
  s.cameras.push_back(look_at({0.0, 0.5 * half, 2.6 * half}, {0.0, 0.0, 0.0}, 45.0, size));
  // Rays cross several beams; a lower exposure keeps the tone curve informative.
  s.output.exposure = count > 500 ? 0.15 : 0.3;
  BenchScene bs = finish("beams_" + std::to_string(count), std::move(s), size);
  bs.max_march_samples = count > 500 ? 64 : 128;
  bs.coarse_tables = count > 500;
  return bs;
}

}  // namespace

std::vector<BenchScene> full_scene_set(const std::filesystem::path& examples_dir, int size) {
  std::vector<BenchScene> set;
  for (const char* name : {"paper_1set", "paper_5sets", "paper_10sets", "thin_shell"}) {
    set.push_back(from_example(examples_dir, name, size));
  }
  set.push_back(grazing_capsule(size));
  set.push_back(random_beams(100, 100, size));
  set.push_back(random_beams(1000, 1000, size));
  for (const char* d : {"abe", "shell", "linear", "quadratic", "gaussian"}) {
    set.push_back(density_scene(d, size));
  }
  return set;
}

std::vector<BenchScene> quick_scene_set(const std::filesystem::path& examples_dir, int size) {
  std::vector<BenchScene> set;
  set.push_back(from_example(examples_dir, "paper_1set", size));
  set.push_back(from_example(examples_dir, "thin_shell", size));
  set.push_back(grazing_capsule(size));
  return set;
}

}  // namespace beamcast::bench
