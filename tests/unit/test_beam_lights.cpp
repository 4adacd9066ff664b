// Beams that emit light (issue 14, item 1): "emit": true adds the beam's
// light to the scene with the flux of its density's volume integral; photons
// and next-event samples are drawn with density proportional to f; the
// direct pass's points carry the whole flux; the path tracer lights a floor
// under a sphere beam as a point at its centre (the shell theorem).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "gi/gi_scene.hpp"
#include "gi/path_tracer.hpp"
#include "gi/photon_map.hpp"
#include "protocol/errors.hpp"
#include "protocol/lights/lights.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
constexpr double kPi = std::numbers::pi;

json beam_scene(json beams, json extra = json::object()) {
  json j = {{"beams", std::move(beams)},
            {"occluders", {{{"type", "plane"}, {"point", {0, -5, 0}}, {"normal", {0, 1, 0}}}}},
            {"cameras", {{{"position", {0, 0, 20}}, {"target", {0, 0, 0}}}}}};
  j.update(extra);
  return j;
}

json sphere_beam(double r, const std::string& density, double intensity, bool emit) {
  return {{"type", "sphere"}, {"center", {0, 1, 0}}, {"radius", r}, {"color", {1.0, 0.5, 0.25}},
          {"intensity", intensity}, {"density", density}, {"emit", emit}};
}

ErrorInfo error_of(const json& j) {
  try {
    parse_scene(j, {});
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

LightRandom draw(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  return {u(rng), u(rng), u(rng), u(rng)};
}

TEST(BeamLights, AnEmittingBeamBecomesALightWithTheFluxOfItsDensity) {
  // Linear f = 1 - x: S2 = 1/12, M = 4 pi r^3 / 12; flux = 4 pi c I M / r.
  const double r = 2.0, intensity = 3.0;
  const Scene s = parse_scene(beam_scene(json::array({sphere_beam(r, "linear", intensity, true)})), {});
  ASSERT_EQ(s.lights.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<BeamEmitter>(s.lights[0].shape));
  EXPECT_TRUE(s.has_gi());
  const double m = 4.0 * kPi * r * r * r / 12.0;
  const double flux = 4.0 * kPi * intensity * m / r;
  // The moments come from 4-point Gauss-Legendre on 4096 cells: exact for
  // polynomials up to degree 7, so only rounding is left.
  EXPECT_NEAR(s.lights[0].flux[0], flux, 1e-9 * flux);
  EXPECT_NEAR(s.lights[0].flux[1], 0.5 * flux, 1e-9 * flux);
  EXPECT_NEAR(s.lights[0].flux[2], 0.25 * flux, 1e-9 * flux);

  // A capsule with one cap, quadratic f = 1 - x^2: S1 = 1/4, S2 = 2/15.
  const json capsule = {{"type", "capsule"}, {"p0", {0, 0, 0}}, {"p1", {3, 0, 0}},
                        {"radius", 1.0},     {"caps", {true, false}}, {"density", "quadratic"},
                        {"emit", true}};
  const Scene c = parse_scene(beam_scene(json::array({capsule})), {});
  ASSERT_EQ(c.lights.size(), 1u);
  const double mc = 2.0 * kPi * 3.0 * 0.25 + 2.0 * kPi * 2.0 / 15.0;
  EXPECT_NEAR(std::get<BeamEmitter>(c.lights[0].shape).volume_mass(), mc, 1e-9 * mc);
  EXPECT_NEAR(c.lights[0].flux[0], 4.0 * kPi * mc, 1e-9 * mc);

  // Not emitting: no light, no GI passes.
  const Scene quiet = parse_scene(beam_scene(json::array({sphere_beam(r, "linear", intensity, false)})), {});
  EXPECT_TRUE(quiet.lights.empty());
  EXPECT_FALSE(quiet.has_gi());
}

TEST(BeamLights, TheBeamLightIsNotATypeClientsWrite) {
  for (std::string_view t : light_types()) EXPECT_NE(t, "beam");
  const ErrorInfo bad_type = error_of(beam_scene(
      json::array(), {{"lights", {{{"type", "beam"}, {"position", {0, 0, 0}}}}}}));
  EXPECT_EQ(bad_type.code, "invalid_value");
  EXPECT_EQ(bad_type.path, "/lights/0/type");
  EXPECT_NE(bad_type.message.find("\"quad\""), std::string::npos) << bad_type.message;
  json b = sphere_beam(1.0, "linear", 1.0, true);
  b["emit"] = 1;
  const ErrorInfo bad_emit = error_of(beam_scene(json::array({b})));
  EXPECT_EQ(bad_emit.path, "/beams/0/emit");
  EXPECT_FALSE(bad_emit.message.empty());
}

TEST(BeamLights, PhotonsLeaveWithTheDensityInUniformDirections) {
  const Scene s = parse_scene(beam_scene(json::array({sphere_beam(2.0, "linear", 1.0, true)})), {});
  const auto& e = std::get<BeamEmitter>(s.lights[0].shape);
  std::mt19937_64 rng(7);
  constexpr int kN = 200000;
  double sum_x = 0.0;
  Vec3 sum_dir{};
  for (int i = 0; i < kN; ++i) {
    const Emission em = e.emit(draw(rng));
    ASSERT_EQ(em.weight, 1.0);
    sum_x += length(em.origin - Vec3{0.0, 1.0, 0.0}) / 2.0;
    sum_dir = sum_dir + em.dir;
  }
  // x has density f(x) x^2 / S2: mean S3 / S2 = (1/20) / (1/12) = 0.6, and
  // E[x^2] = S4 / S2 = 0.4, so sd 0.2 and the standard error of the mean
  // over 200 000 draws 4.5e-4: 2.3e-3 is 5 of them.
  EXPECT_NEAR(sum_x / kN, 0.6, 2.3e-3);
  // Uniform directions: each component has mean 0 and sd 1/sqrt(3); the
  // standard error is 1.3e-3, 6.5e-3 is 5 of them.
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(sum_dir[k] / kN, 0.0, 6.5e-3);

  // A capsule: the share of points in the cylinder is its share of the mass,
  // and none lies outside the body.
  const json capsule = {{"type", "capsule"}, {"p0", {0, 0, 0}}, {"p1", {3, 0, 0}},
                        {"radius", 1.0},     {"density", "quadratic"}, {"emit", true}};
  const Scene c = parse_scene(beam_scene(json::array({capsule})), {});
  const auto& ce = std::get<BeamEmitter>(c.lights[0].shape);
  const double cyl = 2.0 * kPi * 3.0 * 0.25, cap = 2.0 * kPi * 2.0 / 15.0;
  int in_cylinder = 0;
  for (int i = 0; i < kN; ++i) {
    const Vec3 p = ce.emit(draw(rng)).origin;
    const double t = std::clamp(p[0], 0.0, 3.0);
    ASSERT_LE(length(p - Vec3{t, 0.0, 0.0}), 1.0 + 1e-9);
    if (p[0] >= 0.0 && p[0] <= 3.0) ++in_cylinder;
  }
  // Binomial: p = cyl / (cyl + 2 cap) = 0.85, sd sqrt(p (1 - p) / N) = 8e-4;
  // 4e-3 is 5 of them.
  EXPECT_NEAR(static_cast<double>(in_cylinder) / kN, cyl / (cyl + 2.0 * cap), 4e-3);
}

TEST(BeamLights, DirectPointsCarryTheWholeFlux) {
  const Scene s = parse_scene(beam_scene(json::array({sphere_beam(2.0, "linear", 1.0, true)})), {});
  const auto sp = std::get<BeamEmitter>(s.lights[0].shape).direct_points(16);
  ASSERT_EQ(sp.size(), 1u);
  EXPECT_EQ(sp[0].position, (Vec3{0.0, 1.0, 0.0}));
  EXPECT_NEAR(sp[0].scale, 1.0 / (4.0 * kPi), 1e-15);
  const json capsule = {{"type", "capsule"}, {"p0", {0, 0, 0}}, {"p1", {3, 0, 0}},
                        {"radius", 1.0},     {"density", "quadratic"}, {"emit", true}};
  const Scene c = parse_scene(beam_scene(json::array({capsule})), {});
  const auto cp = std::get<BeamEmitter>(c.lights[0].shape).direct_points(16);
  ASSERT_EQ(cp.size(), 16u);
  double total = 0.0;
  for (const DirectPoint& p : cp) {
    EXPECT_EQ(p.mode, DirectPoint::Mode::kIsotropic);
    total += p.scale;
  }
  EXPECT_NEAR(total, 1.0 / (4.0 * kPi), 1e-12);
  // The caps' points at their half-balls' centroids: (r / 2) S3 / S2 with
  // S3 = 1/4 - 1/6 = 1/12 and S2 = 2/15: 0.3125 beyond each end.
  EXPECT_NEAR(cp[14].position[0], -0.3125, 1e-6);
  EXPECT_NEAR(cp[15].position[0], 3.3125, 1e-6);
}

// Every photon from a beam inside a closed sphere hits its wall once straight
// from the beam: their powers sum to the beam's flux.
TEST(BeamLights, PhotonsCarryTheBeamsFlux) {
  json scene = {{"beams", json::array({sphere_beam(1.5, "quadratic", 2.0, true)})},
                {"occluders", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 6.0},
                                {"albedo", {0.0, 0.0, 0.0}}}}},
                {"gi", {{"photons", 20000}, {"caustic_photons", 0}}},
                {"cameras", {{{"position", {0, 0, 0.5}}, {"target", {0, 0, 0}}}}}};
  const Scene s = parse_scene(scene, {});
  const GiScene surfaces(s);
  const PhotonMaps maps = trace_photons(s, surfaces);
  double sum = 0.0;
  for (const Photon& p : maps.global) sum += p.power[0];
  EXPECT_EQ(maps.global.size(), 20000u);
  EXPECT_NEAR(sum, s.lights[0].flux[0], 1e-4 * s.lights[0].flux[0]);  // float powers
}

// A floor under a sphere beam that it sees whole: the path tracer's radiance
// at the point below the centre is rho / pi x flux / (4 pi h^2) (the shell
// theorem: a spherically symmetric emitter lights what sees all of it as a
// point at its centre); an open floor sees no other surface.
TEST(BeamLights, AFloorUnderASphereBeamIsLitAsByAPointAtItsCentre) {
  const double rho = 0.5, h = 3.0;
  json scene = {{"beams", {{{"type", "sphere"}, {"center", {0, h, 0}}, {"radius", 1.0},
                            {"density", "abe"}, {"intensity", 5.0}, {"emit", true}}}},
                {"occluders", {{{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 1, 0}},
                                {"albedo", {rho, rho, rho}}}}},
                {"cameras", {{{"position", {2, 1, 0.3}}, {"target", {0, 0, 0}}, {"fov_y", 0.5},
                              {"width", 32}, {"height", 32}}}}};
  const Scene s = parse_scene(scene, {});
  const GiScene gi(s);
  PathTraceOptions po;
  po.spp = 64;
  const std::vector<Color> img = path_trace(gi, s.cameras[0], po);
  double sum = 0.0, sum2 = 0.0;
  for (const Color& c : img) {
    sum += c[0];
    sum2 += c[0] * c[0];
  }
  const double n = static_cast<double>(img.size());
  const double mean = sum / n;
  const double se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1.0));
  // The pixels see a spot 0.02 wide around the origin, where cos / d^2
  // varies by under 1e-4.
  const double expected = rho / kPi * s.lights[0].flux[0] / (4.0 * kPi * h * h);
  std::printf("floor under a sphere beam: %.6f expected %.6f (%+.3f%%, standard error %.3f%%)\n",
              mean, expected, 100.0 * (mean / expected - 1.0), 100.0 * se / expected);
  EXPECT_LT(se / expected, 0.005);
  EXPECT_NEAR(mean, expected, 5.0 * se);
}

}  // namespace
}  // namespace beamcast
