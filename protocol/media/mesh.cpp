#include "protocol/media/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "protocol/json_reader.hpp"
#include "protocol/mesh_obj.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

using namespace json_read;

namespace {

// Refuses ("unknown_field") any of `fields` present in `o`: "<field><why>".
void refuse(const ObjectReader& o, std::initializer_list<const char*> fields,
            const std::string& why) {
  for (const char* f : fields) {
    if (auto v = o.optional(f)) fail("unknown_field", v->path, std::string(f) + why);
  }
}

std::string format_point(const Vec3& p) {
  return "(" + format_number(p[0]) + ", " + format_number(p[1]) + ", " + format_number(p[2]) + ")";
}

// Keeps a mesh region's triangles if they bound a volume: every edge (its
// vertices welded by exact position) shared by exactly two triangles that
// run it in opposite directions. Rewinds them outwards if the enclosed
// signed volume is negative. Errors "bad_mesh" at `path`.
std::vector<std::array<Vec3, 3>> closed_surface(std::vector<std::array<Vec3, 3>> tris,
                                                const std::string& path) {
  std::map<Vec3, int> ids;
  auto id = [&](const Vec3& p) {
    return ids.emplace(p, static_cast<int>(ids.size())).first->second;
  };
  struct Run {
    int n = 0;  // triangles running this directed edge
    Vec3 p, q;  // its ends, for messages
  };
  std::map<std::pair<int, int>, Run> edges;
  std::vector<std::array<Vec3, 3>> kept;
  for (const auto& t : tris) {
    const int a = id(t[0]), b = id(t[1]), c = id(t[2]);
    if (a == b || b == c || c == a) continue;  // degenerate: bounds nothing
    kept.push_back(t);
    const std::array<std::pair<int, int>, 3> run{{{a, b}, {b, c}, {c, a}}};
    for (std::size_t i = 0; i < 3; ++i) {
      Run& e = edges[run[i]];
      ++e.n;
      e.p = t[i];
      e.q = t[(i + 1) % 3];
    }
  }
  if (kept.empty()) fail("bad_mesh", path, "a medium region's mesh has no triangles");
  for (const auto& [e, r] : edges) {
    const auto back = edges.find({e.second, e.first});
    const int n = r.n, m = back == edges.end() ? 0 : back->second.n;
    const Vec3& p = r.p;
    const Vec3& q = r.q;
    if (n + m == 1) {
      fail("bad_mesh", path,
           "the mesh is open: its edge from " + format_point(p) + " to " + format_point(q) +
               " borders one triangle; a medium region needs a closed surface (every edge "
               "shared by exactly two triangles)");
    }
    if (n != 1 || m != 1) {
      fail("bad_mesh", path,
           "the edge from " + format_point(p) + " to " + format_point(q) +
               (n + m > 2 ? " borders more than two triangles"
                          : " is run the same way by both its triangles (inconsistent winding)") +
               "; a medium region needs a closed, consistently wound surface");
    }
  }
  // Signed volume, about the first vertex (exact for a closed surface,
  // less cancellation than about the origin).
  const Vec3 o = kept.front()[0];
  double volume = 0.0;
  for (const auto& t : kept) volume += dot(t[0] - o, cross(t[1] - o, t[2] - o)) / 6.0;
  if (!(std::abs(volume) > 0.0)) fail("bad_mesh", path, "the mesh encloses no volume");
  if (volume < 0.0) {
    for (auto& t : kept) std::swap(t[1], t[2]);
  }
  return kept;
}

std::vector<std::array<Vec3, 3>> read_mesh_region(const ObjectReader& o,
                                                  const SceneLoadOptions& opts,
                                                  std::int64_t* mesh_triangles, std::string* path) {
  const auto file = o.optional("file");
  const auto verts = o.optional("vertices");
  const auto tris = o.optional("triangles");
  std::vector<std::array<Vec3, 3>> out;
  const std::int64_t room = kMaxMediumMeshTriangles - *mesh_triangles;
  if (file) {
    refuse(o, {"vertices", "triangles"},
           ": give a mesh as file or as vertices and triangles, not both");
    *path = file->path;
    const std::string name = read_string(*file);
    if (name.empty()) fail("invalid_value", file->path, "file must be a non-empty relative path");
    const MeshTransform xf = parse_mesh_transform(o, opts.limits);
    const MeshLoadLimits limits{kMaxMediumMeshTriangles, *mesh_triangles,
                                opts.limits.max_abs_coordinate};
    const MeshOccluder mesh = load_obj_mesh(opts.assets_dir, name, xf, limits, file->path);
    for (const auto& t : mesh.triangles) {
      out.push_back({mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]});
    }
  } else {
    refuse(o, {"translate", "scale", "rotation"},
           " is for meshes from a file; give inline vertices in world space");
    if (!verts || !tris) {
      fail("missing_field", o.path_of(verts ? "triangles" : "vertices"),
           "a mesh region needs file, or vertices and triangles");
    }
    *path = tris->path;
    std::vector<Vec3> vs;
    for (const Node& v :
         read_array(*verts, 3 * kMaxMediumMeshTriangles, "max_medium_mesh_triangles")) {
      vs.push_back(check_coordinates(v, read_vec3(v), opts.limits.max_abs_coordinate));
    }
    for (const Node& t : read_array(*tris, room, "max_medium_mesh_triangles")) {
      const std::vector<Node> idx = read_array(t);
      if (idx.size() != 3) fail("invalid_value", t.path, "a triangle is three vertex indices");
      std::array<Vec3, 3> tri;
      for (std::size_t i = 0; i < 3; ++i) {
        const std::int64_t k = read_integer(idx[i]);
        if (k < 0 || k >= static_cast<std::int64_t>(vs.size())) {
          fail("out_of_range", idx[i].path,
               "vertex index " + std::to_string(k) + " is outside [0, " +
                   std::to_string(vs.size()) + ")");
        }
        tri[i] = vs[static_cast<std::size_t>(k)];
      }
      out.push_back(tri);
    }
  }
  *mesh_triangles += static_cast<std::int64_t>(out.size());
  return out;
}

bool lex_less(const Vec3& a, const Vec3& b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

// v . (a x b), each product and sum in this order (the shader's triple() in
// shaders/medium_regions.glsl does the same): swapping a and b gives
// exactly the negated value, so the two triangles of an edge agree on
// which side of it the line passes.
double triple(const Vec3& v, const Vec3& a, const Vec3& b) {
  const double cx = a[1] * b[2] - a[2] * b[1];
  const double cy = a[2] * b[0] - a[0] * b[2];
  const double cz = a[0] * b[1] - a[1] * b[0];
  return v[0] * cx + v[1] * cy + v[2] * cz;
}

// Whether a line passing exactly through the edge (a, b) of a triangle
// facing `back` (v along its normal) counts as passing through the
// triangle: the owner of an edge is decided by the order of its ends, so
// of two triangles facing the same way along the line exactly one counts
// it (one crossing, not two), and of a front- and a back-facing pair (the
// line grazes the surface) both or neither (an entry and an exit).
bool edge_counts(double e, bool back, const Vec3& a, const Vec3& b) {
  const double s = back ? 1.0 : -1.0;
  return s * e > 0.0 || (e == 0.0 && lex_less(a, b) != !back);
}

// Calls f(t, c) for each crossing of the line o + t v (every t) with the
// mesh: c = +1 where it enters (against the outward normal), -1 where it
// leaves. Edge functions of the line against each edge, no tolerance.
template <class F>
void mesh_crossings(const std::vector<std::array<Vec3, 3>>& tris, const Vec3& o, const Vec3& v,
                    F&& f) {
  for (const auto& tri : tris) {
    const Vec3 p0 = tri[0] - o, p1 = tri[1] - o, p2 = tri[2] - o;
    const double e0 = triple(v, p1, p2), e1 = triple(v, p2, p0), e2 = triple(v, p0, p1);
    const double det = e0 + e1 + e2;  // v . n, n = (p1 - p0) x (p2 - p0)
    if (det == 0.0) continue;         // the line lies in the triangle's plane
    const bool back = det > 0.0;
    if (!edge_counts(e0, back, tri[1], tri[2]) || !edge_counts(e1, back, tri[2], tri[0]) ||
        !edge_counts(e2, back, tri[0], tri[1])) {
      continue;
    }
    const Vec3 nrm = cross(p1 - p0, p2 - p0);
    f(dot(nrm, p0) / dot(nrm, v), back ? -1 : 1);
  }
}

// A direction no mesh edge is likely to be parallel to, for inside tests.
constexpr Vec3 kInsideProbe{0.6, 0.64, 0.48};

}  // namespace

MeshRegion MeshRegion::parse(const RegionParse& in) {
  std::string path;
  return from_triangles(
      closed_surface(read_mesh_region(in.fields, in.opts, in.mesh_triangles, &path), path));
}

MeshRegion MeshRegion::from_triangles(std::vector<std::array<Vec3, 3>> tris) {
  MeshRegion r;
  r.triangles = std::move(tris);
  for (const auto& t : r.triangles) {
    for (const Vec3& p : t) r.box.grow(p);
  }
  return r;
}

bool MeshRegion::contains(const Vec3& x) const {
  for (std::size_t i = 0; i < 3; ++i) {
    if (x[i] < box.lo[i] || x[i] > box.hi[i]) return false;
  }
  int inside = 0;  // crossings before x: entries minus exits
  mesh_crossings(triangles, x, kInsideProbe, [&](double t, int c) {
    if (t < 0.0) inside += c;
  });
  return inside > 0;
}

double MeshRegion::chord(const Vec3& o, const Vec3& v, double t0, double t1) const {
  double a = t0, b = t1;
  clip_to_box(box, o, v, &a, &b);  // [a, b] is finite
  if (!(b > a)) return 0.0;
  // Inside-ness along the line is the sum of c H(t - t_c) over the
  // crossings, so its integral over [a, b] is the sum of c (b - clamp(t_c)).
  double sum = 0.0;
  mesh_crossings(triangles, o, v,
                 [&](double t, int c) { sum += c * (b - std::clamp(t, a, b)); });
  return std::clamp(sum, 0.0, b - a);
}

double MeshRegion::exit(const Vec3& o, const Vec3& v) const {
  double a = 0.0, b = std::numeric_limits<double>::infinity();
  clip_to_box(box, o, v, &a, &b);
  if (!(b > a)) return -1.0;
  double last = -1.0;  // the last crossing of a closed surface is an exit
  mesh_crossings(triangles, o, v, [&](double t, int c) {
    if (c < 0 && t > last) last = t;
  });
  return last > 0.0 ? last : -1.0;
}

void MeshRegion::crossings(const Vec3& o, const Vec3& v, double t_end,
                           std::vector<double>* out) const {
  double a = 0.0, b = t_end;
  clip_to_box(box, o, v, &a, &b);
  if (!(b > a)) return;
  mesh_crossings(triangles, o, v, [&](double t, int) {
    if (t > 0.0 && t < t_end) out->push_back(t);
  });
}

}  // namespace beamcast
