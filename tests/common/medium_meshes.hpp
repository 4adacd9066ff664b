// Closed triangle meshes as JSON for regions of medium ("type": "mesh",
// issue 15): a cube whose faces are split along diagonals through their
// centres, and the same cube with a dent (concave).
#pragma once

#include <nlohmann/json.hpp>
#include <utility>

namespace beamcast::test {

using nlohmann::json;

// The cube [-1, 1]^3 as 12 outward-wound triangles; each face split along
// a diagonal through its centre, so axis rays through the cube's centre
// cross exactly on an edge.
inline json cube_vertices() {
  json v = json::array();
  for (int i = 0; i < 8; ++i) v.push_back({i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1});
  return v;
}
inline json cube_triangles() {
  return {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
          {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
}

// The cube with its top face (y = 1) replaced by a dent down to the centre:
// four triangles to the vertex (0, 0, 0) (index 8). Not convex: lines over
// the dent leave and enter again.
inline json dented_triangles() {
  json t = json::array();
  for (const json& tri : cube_triangles()) {
    if (tri == json{2, 6, 7} || tri == json{2, 7, 3}) continue;  // the top face
    t.push_back(tri);
  }
  // The top face's rim (2, 6, 7, 3) wound as the face was, each edge to the dent.
  for (auto [a, b] : {std::pair{2, 6}, {6, 7}, {7, 3}, {3, 2}}) t.push_back({a, b, 8});
  return t;
}

inline json mesh_region(json vertices, json triangles, double sigma_a = 1.0) {
  return {{"type", "mesh"},
          {"vertices", std::move(vertices)},
          {"triangles", std::move(triangles)},
          {"sigma_a", sigma_a}};
}

}  // namespace beamcast::test
