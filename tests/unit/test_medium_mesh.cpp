// Regions of medium bounded by closed triangle meshes (issue 15, item 1;
// seed 001 section 5.7: optical depth from boundary crossings, front faces
// enter, back faces leave): exact chords, lines through edges counted
// once, either winding, and open or inconsistent meshes refused with the
// path of the bad field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <utility>

#include "protocol/errors.hpp"
#include "protocol/scene_json.hpp"
#include "tests/common/medium_meshes.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::cube_triangles;
using test::cube_vertices;
using test::dented_triangles;
using test::mesh_region;

json scene_with(json region) {
  return {{"beams", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}}}},
          {"media", json::array({std::move(region)})},
          {"cameras", {{{"position", {0, 0, 5}}, {"target", {0, 0, 0}}}}}};
}

ErrorInfo error_of(const json& j, const SceneLoadOptions& opts = {}) {
  try {
    parse_scene(j, opts);
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "scene was accepted: " << j.dump();
  return {};
}

// The optical depth along o + t v, t in [0, len], by a midpoint sum of
// sigma_t over n steps (the point test, independent of the chords).
double midpoint_depth(const MediumField& f, const Vec3& o, const Vec3& v, double len, int n) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += f.sigma_t(o + ((i + 0.5) * len / n) * v);
  return sum * len / n;
}

// A mesh cube's chords equal the box region's (exact, both; 1e-12 covers
// the crossings' rounding), on random lines and on the axis lines through
// face centres, which cross exactly on a face's diagonal edge: counted
// once there, not twice or never.
TEST(MediumMesh, ACubeMeshHasTheBoxsChords) {
  const Scene mesh = parse_scene(scene_with(mesh_region(cube_vertices(), cube_triangles())), {});
  const Scene box = parse_scene(
      scene_with({{"type", "box"}, {"min", {-1, -1, -1}}, {"max", {1, 1, 1}}, {"sigma_a", 1.0}}),
      {});
  ASSERT_EQ(mesh.media.size(), 1u);
  EXPECT_EQ(mesh.media[0].gpu_triangles().size(), 12u);
  const MediumField fm = mesh.medium_field(), fb = box.medium_field();
  for (const Vec3& v : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{-1, 0, 0}}) {
    const Vec3 o = -3.0 * v;
    EXPECT_DOUBLE_EQ(fm.optical_depth(o, v, 0.0, 6.0), 2.0) << v[0] << v[1] << v[2];
    EXPECT_DOUBLE_EQ(fm.optical_depth(o, v, 0.0, 2.5), 0.5);              // ends inside
    EXPECT_DOUBLE_EQ(fm.optical_depth(Vec3{0, 0, 0}, v, 0.0, 9.0), 1.0);  // starts inside
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 o{3 * u(rng), 3 * u(rng), 3 * u(rng)};
    const Vec3 v = normalize(Vec3{u(rng), u(rng), u(rng)});
    const double t0 = 2 * u(rng), t1 = t0 + 4 + 2 * u(rng);
    EXPECT_NEAR(fm.optical_depth(o, v, t0, t1), fb.optical_depth(o, v, t0, t1), 1e-12);
    EXPECT_EQ(fm.sigma_t(o), fb.sigma_t(o));
    EXPECT_NEAR(fm.last_exit(o, v), fb.last_exit(o, v), 1e-12);
  }
}

// A concave mesh (the cube with a dent to its centre): chords against a
// midpoint sum of the point test over 1e5 steps (its error is about one
// step's share of each boundary crossing, 6/1e5 per crossing: 1e-4 bounds
// it), the same result from either winding (rewound outwards on load).
TEST(MediumMesh, ConcaveMeshesAndEitherWinding) {
  json verts = cube_vertices();
  verts.push_back({0, 0, 0});
  const Scene s = parse_scene(scene_with(mesh_region(verts, dented_triangles(), 0.7)), {});
  json flipped = dented_triangles();
  for (json& t : flipped) std::swap(t[1], t[2]);
  const Scene f = parse_scene(scene_with(mesh_region(verts, flipped, 0.7)), {});
  const MediumField fs = s.medium_field(), ff = f.medium_field();
  EXPECT_EQ(fs.sigma_t({0.0, 0.5, 0.0}), 0.0);  // in the dent
  EXPECT_EQ(fs.sigma_t({0.0, -0.5, 0.0}), 0.7);
  EXPECT_EQ(fs.sigma_t({0.9, 0.5, 0.0}), 0.7);  // beside the dent
  // Across the dent: in (x -1..-0.5 under the dent's slope), out, in again.
  const Vec3 o{-3.0, 0.5, 0.1}, v{1.0, 0.0, 0.0};
  EXPECT_NEAR(fs.optical_depth(o, v, 0.0, 6.0), 0.7 * 1.0, 1e-12);  // |x| >= 0.5 inside
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const Vec3 p{2.5 * u(rng), 2.5 * u(rng), 2.5 * u(rng)};
    const Vec3 d = normalize(Vec3{u(rng), u(rng), u(rng)});
    const double exact = fs.optical_depth(p, d, 0.0, 5.0);
    EXPECT_NEAR(exact, midpoint_depth(fs, p, d, 5.0, 100000), 1e-4);
    EXPECT_NEAR(ff.optical_depth(p, d, 0.0, 5.0), exact, 1e-12);
  }
}

// An OBJ file below the assets directory, moved and scaled like a mesh
// occluder; the same file with a face missing is refused at "file".
TEST(MediumMesh, MeshRegionsFromObjFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "beamcast_medium_mesh";
  std::filesystem::create_directories(dir);
  auto write = [&](const char* name, int skip) {
    std::ofstream out(dir / name);
    for (const json& p : cube_vertices()) out << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    int i = 0;
    for (const json& t : cube_triangles()) {
      if (i++ != skip)
        out << "f " << t[0].get<int>() + 1 << " " << t[1].get<int>() + 1 << " "
            << t[2].get<int>() + 1 << "\n";
    }
  };
  write("cube.obj", -1);
  write("open.obj", 5);
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  const Scene s = parse_scene(scene_with({{"type", "mesh"},
                                          {"file", "cube.obj"},
                                          {"translate", {1, 0, 0}},
                                          {"scale", 2.0},
                                          {"sigma_a", 0.5}}),
                              opts);
  EXPECT_DOUBLE_EQ(s.medium_field().optical_depth({-5, 0.3, 0.2}, {1, 0, 0}, 0.0, 10.0), 2.0);
  const ErrorInfo e = error_of(scene_with({{"type", "mesh"}, {"file", "open.obj"}}), opts);
  EXPECT_EQ(e.code, "bad_mesh");
  EXPECT_EQ(e.path, "/media/0/file");
  EXPECT_NE(e.message.find("open"), std::string::npos) << e.message;
  std::filesystem::remove_all(dir);
}

TEST(MediumMesh, BadMeshesAreRefusedWithTheirPath) {
  json open = cube_triangles();
  open.erase(open.begin() + 3);
  json twisted = cube_triangles();
  std::swap(twisted[4][1], twisted[4][2]);
  json flat = json::array({{0, 1, 3}, {0, 3, 1}});  // two faces of nothing
  json bad_index = cube_triangles();
  bad_index[3][1] = 8;
  struct Case {
    json region;
    std::string code, path, says;
  };
  const Case cases[] = {
      {mesh_region(cube_vertices(), open), "bad_mesh", "/media/0/triangles", "open"},
      {mesh_region(cube_vertices(), twisted), "bad_mesh", "/media/0/triangles", "winding"},
      {mesh_region(cube_vertices(), flat), "bad_mesh", "/media/0/triangles", "no volume"},
      {mesh_region(cube_vertices(), bad_index), "out_of_range", "/media/0/triangles/3/1", ""},
      {mesh_region(cube_vertices(), {{0, 1}}), "invalid_value", "/media/0/triangles/0", ""},
      {{{"type", "mesh"}, {"vertices", cube_vertices()}},
       "missing_field",
       "/media/0/triangles",
       ""},
      {{{"type", "mesh"}, {"file", "a.obj"}, {"vertices", cube_vertices()}},
       "unknown_field",
       "/media/0/vertices",
       ""},
      {{{"type", "mesh"}, {"file", "a.obj"}}, "forbidden_path", "/media/0/file", ""},
      {{{"type", "box"}, {"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"triangles", json::array()}},
       "unknown_field",
       "/media/0/triangles",
       ""},
      {mesh_region({{0, 0, 1e300}}, {{0, 0, 0}}), "out_of_range", "/media/0/vertices/0/2", ""},
  };
  for (const Case& c : cases) {
    const ErrorInfo e = error_of(scene_with(c.region));
    EXPECT_EQ(e.code, c.code) << c.region.dump() << ": " << e.message;
    EXPECT_EQ(e.path, c.path) << c.region.dump() << ": " << e.message;
    EXPECT_NE(e.message.find(c.says), std::string::npos) << e.message;
  }
  // The scene's mesh regions together: at most kMaxMediumMeshTriangles.
  json many = scene_with(mesh_region(cube_vertices(), cube_triangles()));
  const int copies = static_cast<int>(kMaxMediumMeshTriangles / 12) + 1;
  json tris = json::array();
  json verts = json::array();
  for (int i = 0; i < copies; ++i) {
    for (json p : cube_vertices()) {
      p[0] = p[0].get<double>() + 3.0 * i;
      verts.push_back(p);
    }
    for (json t : cube_triangles()) {
      for (json& k : t) k = k.get<int>() + 8 * i;
      tris.push_back(t);
    }
  }
  many["media"][0] = mesh_region(verts, tris);
  const ErrorInfo e = error_of(many);
  EXPECT_EQ(e.code, "limit_exceeded") << e.message;
  EXPECT_EQ(e.path, "/media/0/triangles");
}

}  // namespace
}  // namespace beamcast
