// The quad occluder's module: parsing with JSON-pointer errors, bounds, GPU
// triangles and the reference intersection (one- and two-sided).
#include "protocol/occluders/quad.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json scene_with(json quad) {
  return {{"occluders", json::array({std::move(quad)})}, {"cameras", json::array({json::object()})}};
}

json floor_quad() {
  return {{"type", "quad"}, {"corner", {-1, 0, 1}}, {"edge_u", {2, 0, 0}}, {"edge_v", {0, 0, -2}}};
}

json with_field(const char* key, json value) {
  json q = floor_quad();
  q[key] = std::move(value);
  return q;
}

ErrorInfo error_of(const json& j) {
  try {
    parse_scene(j, SceneLoadOptions{});
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

TEST(Quad, ParsesWithDefaults) {
  json q = floor_quad();
  q["albedo"] = {0.5, 0.25, 1.0};
  const Scene s = parse_scene(scene_with(q), SceneLoadOptions{});
  const auto& quad = std::get<QuadOccluder>(s.occluders.at(0).shape);
  EXPECT_EQ(quad.corner, (Vec3{-1, 0, 1}));
  EXPECT_EQ(quad.edge_v, (Vec3{0, 0, -2}));
  EXPECT_TRUE(quad.two_sided);
  EXPECT_EQ(s.occluders[0].albedo, (Color{0.5, 0.25, 1.0}));
  q["sides"] = 1;
  EXPECT_FALSE(std::get<QuadOccluder>(parse_scene(scene_with(q), {}).occluders[0].shape).two_sided);
}

TEST(Quad, BadFieldsNameTheirPointer) {
  struct Bad {
    json quad;
    const char* code;
    const char* path;
  };
  json no_corner = floor_quad();
  no_corner.erase("corner");
  const std::vector<Bad> cases = {
      {no_corner, "missing_field", "/occluders/0/corner"},
      {with_field("edge_v", {4, 0, 0}), "invalid_value", "/occluders/0/edge_v"},
      {with_field("edge_u", {0, 0, 0}), "invalid_value", "/occluders/0/edge_u"},
      // Issue 43: a subnormal edge, and edges whose area underflows.
      {with_field("edge_u", {1e-310, 0, 0}), "out_of_range", "/occluders/0/edge_u/0"},
      {with_field("edge_u", {1e-16, 0, 0}), "invalid_value", "/occluders/0/edge_u"},
      {with_field("sides", 3), "invalid_value", "/occluders/0/sides"},
      {with_field("sides", "one"), "wrong_type", "/occluders/0/sides"},
      {with_field("edge_u", {1e300, 0, 0}), "out_of_range",
       "/occluders/0/edge_u/0"},
      {with_field("normal", {0, 1, 0}), "unknown_field", "/occluders/0/normal"},
  };
  for (const Bad& b : cases) {
    const ErrorInfo e = error_of(scene_with(b.quad));
    EXPECT_EQ(e.code, b.code) << b.quad.dump() << ": " << e.message;
    EXPECT_EQ(e.path, b.path) << b.quad.dump() << ": " << e.message;
  }
}

TEST(Quad, BoundsHoldAllFourCorners) {
  const QuadOccluder q{{1, 2, 3}, {2, 0, 0}, {0, 1, -1}, true};
  const Aabb b = q.bounds();
  EXPECT_EQ(b.lo, (Vec3{1, 2, 2}));
  EXPECT_EQ(b.hi, (Vec3{3, 3, 3}));
}

struct Collect final : TriangleSink {
  std::vector<std::array<Vec3, 3>> tris;
  std::vector<bool> one_sided;
  void add(const Vec3& a, const Vec3& b, const Vec3& c, bool os) override {
    tris.push_back({a, b, c});
    one_sided.push_back(os);
  }
};

// Two triangles covering the parallelogram, both facing cross(edge_u, edge_v).
TEST(Quad, GpuTrianglesFaceTheQuadNormal) {
  const QuadOccluder q{{-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, false};
  Collect c;
  q.gpu_triangles(c);
  ASSERT_EQ(c.tris.size(), 2u);
  double area = 0.0;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& t = c.tris[i];
    const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
    EXPECT_GT(n[1], 0.0);  // cross((2,0,0), (0,0,-2)) = (0, 4, 0)
    area += 0.5 * length(n);
    EXPECT_TRUE(c.one_sided[i]);
  }
  EXPECT_DOUBLE_EQ(area, 4.0);
}

TEST(Quad, ReferenceHitsInsideMissesOutside) {
  const QuadOccluder q{{-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, true};
  const Vec3 down{0, -1, 0};
  const auto hit = q.intersect({0.5, 3, -0.5}, down, 0.0, 10.0);
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->t, 3.0);
  EXPECT_DOUBLE_EQ(hit->n[1], 1.0);
  // Just outside each edge (1e-9 beyond), and beyond t_max.
  EXPECT_FALSE(q.intersect({1.0 + 1e-9, 3, 0}, down, 0.0, 10.0));
  EXPECT_FALSE(q.intersect({0, 3, 1.0 + 1e-9}, down, 0.0, 10.0));
  EXPECT_FALSE(q.intersect({-1.0 - 1e-9, 3, 0}, down, 0.0, 10.0));
  EXPECT_FALSE(q.intersect({0, 3, -1.0 - 1e-9}, down, 0.0, 10.0));
  EXPECT_FALSE(q.intersect({0, 3, 0}, down, 0.0, 2.5));
  // Parallel to the plane: no hit.
  EXPECT_FALSE(q.intersect({0, 0, 0}, {1, 0, 0}, 0.0, 10.0));
}

TEST(Quad, OneSidedIsSeenOnlyAgainstItsNormal) {
  QuadOccluder q{{-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, false};  // normal +y
  EXPECT_TRUE(q.intersect({0, 3, 0}, {0, -1, 0}, 0.0, 10.0));   // from above: front
  EXPECT_FALSE(q.intersect({0, -3, 0}, {0, 1, 0}, 0.0, 10.0));  // from below: back
  q.two_sided = true;
  EXPECT_TRUE(q.intersect({0, -3, 0}, {0, 1, 0}, 0.0, 10.0));
}

TEST(Quad, ListedInTheCapabilities) {
  const json caps = scene_capabilities();
  const auto& types = caps.at("occluder_types");
  EXPECT_NE(std::find(types.begin(), types.end(), "quad"), types.end());
}

}  // namespace
}  // namespace beamcast
