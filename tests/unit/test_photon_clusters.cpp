// Photon clusters (gi/photon_clusters.hpp): power is kept, surfaces the
// splat tells apart stay apart, and for the Epanechnikov kernel a cluster's
// disk (centroid, summed power) sums what its photons would but for their
// spread about the centroid.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gi/photon_cache.hpp"
#include "gi/photon_clusters.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

Photon photon(double x, double y, double z, double power, const float n[3], int bounces = 1) {
  Photon p{};
  p.p[0] = static_cast<float>(x);
  p.p[1] = static_cast<float>(y);
  p.p[2] = static_cast<float>(z);
  for (int k = 0; k < 3; ++k) {
    p.power[k] = static_cast<float>(power * (1.0 + 0.5 * k));  // channels differ
    p.n[k] = n[k];
  }
  p.bounces = static_cast<std::uint16_t>(bounces);
  return p;
}

constexpr float kUp[3] = {0.0f, 1.0f, 0.0f};
constexpr float kDown[3] = {0.0f, -1.0f, 0.0f};

// The Epanechnikov weight (unnormalized) of a disk at distance^2 d2.
double epanechnikov(double d2, double r) { return std::max(0.0, 1.0 - d2 / (r * r)); }

// Photons spread over a floor patch of 4 x 4 radii, random powers.
std::vector<Photon> floor_photons(int count, double r, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-2.0 * r, 2.0 * r), w(0.5, 1.5);
  std::vector<Photon> out;
  for (int i = 0; i < count; ++i) out.push_back(photon(u(rng), 0.0, u(rng), w(rng), kUp));
  return out;
}

TEST(PhotonClusters, ZeroCellDrawsEveryPhotonItsOwnDisk) {
  const auto photons = floor_photons(100, 1.0, 1);
  const auto disks = cluster_photons(photons, photons.size(), false, Vec3{0, 0, 0}, {1.0, 0.0, 2.0});
  ASSERT_EQ(disks.size(), photons.size());
  for (std::size_t i = 0; i < disks.size(); ++i) {
    EXPECT_EQ(disks[i].position[0], photons[i].p[0]);
    EXPECT_EQ(disks[i].power[1], 2.0f * photons[i].power[1]);  // power_scale
  }
}

TEST(PhotonClusters, PowerIsKeptAndPhotonsMerge) {
  const double r = 1.0;
  const auto photons = floor_photons(4000, r, 2);
  const auto disks = cluster_photons(photons, photons.size(), false, Vec3{0.3, 0, -0.2},
                                     {r, 0.25, 1.0});
  // 4 x 4 radii at cells of a quarter radius: at most 17 x 17 cells.
  EXPECT_LE(disks.size(), 17u * 17u);
  EXPECT_GE(disks.size(), 16u * 16u);
  for (int k = 0; k < 3; ++k) {
    double in = 0.0, out = 0.0;
    for (const Photon& p : photons) in += p.power[k];
    for (const SplatDisk& d : disks) out += d.power[k];
    EXPECT_NEAR(out, in, 1e-5 * in) << "channel " << k;
  }
}

// Where every photon of a cluster lies within the radius of x, sum_i P_i
// w(|x - p_i|) = P w(|x - c|) - P s^2 / r^2 for the Epanechnikov profile
// w(d) = 1 - d^2 / r^2 (summed over channels: the centroid c is weighted by
// the photons' summed power; s^2 their mean squared distance from it). One
// cell's photons, x within half a radius of them: all inside; the
// difference is that term to float rounding (1e-4 relative), and at most
// P h^2 / (2 r^2) for a cell of side h (1/32 of P at h = r / 4).
TEST(PhotonClusters, EpanechnikovSumDiffersByThePhotonsSpread) {
  const double r = 1.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> in_cell(0.01, 0.24), w(0.5, 1.5), around(-0.4, 0.6);
  std::vector<Photon> photons;
  for (int i = 0; i < 200; ++i) photons.push_back(photon(in_cell(rng), 0.0, in_cell(rng), w(rng), kUp));
  const auto disks = cluster_photons(photons, photons.size(), false, Vec3{0, 0, 0}, {r, 0.25, 1.0});
  ASSERT_EQ(disks.size(), 1u);
  const SplatDisk& d = disks[0];
  double power = 0.0, spread = 0.0;
  for (const Photon& p : photons) {
    const double pw = p.power[0] + p.power[1] + p.power[2];
    power += pw;
    spread += pw * ((p.p[0] - d.position[0]) * (p.p[0] - d.position[0]) +
                    (p.p[2] - d.position[2]) * (p.p[2] - d.position[2]));
  }
  spread /= power;
  EXPECT_NEAR(d.power[0] + d.power[1] + d.power[2], power, 1e-5 * power);
  EXPECT_GT(spread, 1e-3);
  EXPECT_LT(spread, 0.25 * 0.25 / 2.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double x = around(rng), z = around(rng);
    double direct = 0.0;
    for (const Photon& p : photons) {
      const double d2 = (p.p[0] - x) * (p.p[0] - x) + (p.p[2] - z) * (p.p[2] - z);
      ASSERT_LT(d2, r * r);
      direct += (p.power[0] + p.power[1] + p.power[2]) * epanechnikov(d2, r);
    }
    const double dx = d.position[0] - x, dz = d.position[2] - z;
    const double clustered = power * epanechnikov(dx * dx + dz * dz, r);
    EXPECT_NEAR(clustered - direct, power * spread / (r * r), 1e-4 * direct);
  }
}

TEST(PhotonClusters, SurfacesTheSplatTellsApartStayApart) {
  const double r = 1.0;
  std::vector<Photon> photons;
  // A thin wall's two sides (opposite normals), and a slab's top 0.15 r over
  // its floor (beyond the plane test's 0.1 r): all in one cell.
  photons.push_back(photon(0.01, 0.0, 0.01, 1.0, kUp));
  photons.push_back(photon(0.02, 0.0, 0.02, 1.0, kDown));
  photons.push_back(photon(0.03, 0.15, 0.03, 1.0, kUp));
  // Straight from the light: its own disk (the direct pass may skip it).
  photons.push_back(photon(0.04, 0.0, 0.04, 1.0, kUp, 0));
  const auto disks = cluster_photons(photons, photons.size(), false, Vec3{0, 0, 0}, {r, 0.25, 1.0});
  EXPECT_EQ(disks.size(), 4u);
  // With direct photons skipped, and only the first 2 kept photons drawn.
  EXPECT_EQ(cluster_photons(photons, photons.size(), true, Vec3{0, 0, 0}, {r, 0.25, 1.0}).size(), 3u);
  EXPECT_EQ(cluster_photons(photons, 2, true, Vec3{0, 0, 0}, {r, 0.25, 1.0}).size(), 2u);
  // The same photons: the same disks, in the order of their first photon.
  const auto again = cluster_photons(photons, photons.size(), false, Vec3{0, 0, 0}, {r, 0.25, 1.0});
  for (std::size_t i = 0; i < disks.size(); ++i) {
    EXPECT_EQ(disks[i].normal[1], again[i].normal[1]);
    EXPECT_EQ(disks[i].position[1], again[i].position[1]);
  }
  EXPECT_EQ(disks[1].normal[1], -1.0f);
  EXPECT_EQ(disks[3].position[3], 1.0f);  // marked straight from the light
}

// The disks are kept with the cached maps: the same options give the same
// set (a camera-only change clusters nothing again), other options (the
// preview's drawn share) their own; the bytes count them.
TEST(PhotonClusters, TheCacheKeepsTheDisksWithTheMaps) {
  const nlohmann::json j = {
      {"occluders", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}}}},
      {"lights", {{{"type", "point"}, {"position", {0, 0, 0}}, {"power", 1.0}}}},
      {"gi", {{"photons", 5000}, {"caustic_photons", 0}}},
      {"cameras", {{{"position", {0, 0, 0.5}}, {"target", {0, 0, 0}}}}}};
  const Scene scene = parse_scene(j, {});
  PhotonCache cache;
  const auto maps = cache.get(scene);
  const std::size_t before = cache.bytes();
  const SplatDiskOptions all{false, 1.0, 0.3, 0.1, 0.35};
  const auto a = cache.disks(maps, all);
  EXPECT_EQ(a->photons, static_cast<std::int64_t>(maps->global.size()));
  EXPECT_LT(a->disks.size(), maps->global.size());
  EXPECT_EQ(cache.bytes(), before + a->disks.size() * sizeof(SplatDisk));
  EXPECT_EQ(cache.disks(maps, all), a);
  SplatDiskOptions quarter = all;
  quarter.share = 0.25;
  const auto b = cache.disks(maps, quarter);
  EXPECT_NE(b, a);
  EXPECT_LT(b->disks.size(), a->disks.size());
  EXPECT_EQ(b->photons, a->photons);
  EXPECT_EQ(cache.disks(maps, all), a);  // still kept
}

}  // namespace
}  // namespace beamcast
