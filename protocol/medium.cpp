#include "protocol/medium.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <utility>

#include "protocol/json_reader.hpp"
#include "protocol/mesh_obj.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

using namespace json_read;

double schlick_k_from_g(double g) { return 1.55 * g - 0.55 * g * g * g; }

namespace {

// sigma_s, sigma_a and the phase (k or g) of a medium object.
template <class M>
void read_coefficients(const ObjectReader& o, M* m) {
  // Up to 1e6 per unit length: optical depth 1 over a micrometre of a
  // metre-sized scene; above it a float's e^(-sigma t) is 0 everywhere.
  constexpr double kMaxCoefficient = 1e6;
  if (auto v = o.optional("sigma_s")) m->sigma_s = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  if (auto v = o.optional("sigma_a")) m->sigma_a = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  const auto k = o.optional("k");
  const auto g = o.optional("g");
  if (k && g) {
    fail("invalid_value", g->path,
         "give the phase function as k (Schlick) or as g (Henyey-Greenstein), not both");
  }
  if (k) m->k = check_open(*k, read_number(*k), -1.0, 1.0);
  if (g) m->k = schlick_k_from_g(check_closed(*g, read_number(*g), -kSchlickMaxG, kSchlickMaxG));
}

}  // namespace

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

}  // namespace

MediumRegion parse_medium_region(const Node& n, const SceneLoadOptions& opts,
                                 std::int64_t* mesh_triangles) {
  const double max_abs = opts.limits.max_abs_coordinate;
  ObjectReader o(n, "a medium region");
  o.allow_only(std::span<const std::string_view>(kMediumRegionFields));
  MediumRegion r;
  const Node type = o.required("type");
  r.shape = read_enum<MediumRegion::Shape>(type, {{"box", MediumRegion::Shape::kBox},
                                                  {"sphere", MediumRegion::Shape::kSphere},
                                                  {"mesh", MediumRegion::Shape::kMesh}});
  auto point = [&](const Node& v) { return check_coordinates(v, read_vec3(v), max_abs); };
  if (r.shape != MediumRegion::Shape::kMesh) {
    refuse(o, {"vertices", "triangles", "file", "translate", "scale", "rotation"},
           " is for mesh regions");
  }
  if (r.shape == MediumRegion::Shape::kBox) {
    refuse(o, {"center", "radius"}, " is for spheres; a box has min and max");
    r.lo = point(o.required("min"));
    const Node hi = o.required("max");
    r.hi = point(hi);
    for (std::size_t i = 0; i < 3; ++i) {
      if (!(r.hi[i] > r.lo[i])) {
        fail("invalid_value", hi.path, "max must exceed min in every coordinate (an empty box)");
      }
    }
  } else if (r.shape == MediumRegion::Shape::kSphere) {
    refuse(o, {"min", "max"}, " is for boxes; a sphere has center and radius");
    r.lo = point(o.required("center"));
    const Node rad = o.required("radius");
    r.radius = check_positive(rad, read_number(rad));
    if (r.radius > max_abs)
      fail("out_of_range", rad.path, "radius must be <= " + format_number(max_abs));
  } else {
    refuse(o, {"min", "max", "center", "radius"},
           " is for boxes and spheres; a mesh region has its triangles");
    std::string path;
    r.triangles = closed_surface(read_mesh_region(o, opts, mesh_triangles, &path), path);
    Aabb box;
    for (const auto& t : r.triangles) {
      for (const Vec3& p : t) box.grow(p);
    }
    r.lo = box.lo;
    r.hi = box.hi;
  }
  read_coefficients(o, &r);
  return r;
}

namespace {

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

bool MediumRegion::contains(const Vec3& x) const {
  if (shape == Shape::kMesh) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (x[i] < lo[i] || x[i] > hi[i]) return false;
    }
    int inside = 0;  // crossings before x: entries minus exits
    mesh_crossings(triangles, x, kInsideProbe, [&](double t, int c) {
      if (t < 0.0) inside += c;
    });
    return inside > 0;
  }
  if (shape == Shape::kSphere) {
    const Vec3 d = x - lo;
    return dot(d, d) <= radius * radius;
  }
  return x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1] && x[2] >= lo[2] &&
         x[2] <= hi[2];
}

void MediumRegion::clip(const Vec3& o, const Vec3& v, double* a, double* b) const {
  if (shape == Shape::kSphere) {
    const Vec3 oc = lo - o;
    const double tc = dot(oc, v);
    const Vec3 perp = oc - tc * v;
    const double h2 = radius * radius - dot(perp, perp);
    if (!(h2 > 0.0)) {
      *b = *a;
      return;
    }
    const double h = std::sqrt(h2);
    *a = std::max(*a, tc - h);
    *b = std::min(*b, tc + h);
    return;
  }
  for (std::size_t i = 0; i < 3; ++i) {  // a box, or a mesh's bounds
    if (v[i] == 0.0) {
      if (o[i] < lo[i] || o[i] > hi[i]) *b = *a;
      continue;
    }
    const double ta = (lo[i] - o[i]) / v[i], tb = (hi[i] - o[i]) / v[i];
    *a = std::max(*a, std::min(ta, tb));
    *b = std::min(*b, std::max(ta, tb));
  }
}

double MediumRegion::chord(const Vec3& o, const Vec3& v, double t0, double t1) const {
  double a = t0, b = t1;
  clip(o, v, &a, &b);  // a mesh: its bounds, so [a, b] is finite
  if (!(b > a)) return 0.0;
  if (shape != Shape::kMesh) return b - a;
  // Inside-ness along the line is the sum of c H(t - t_c) over the
  // crossings, so its integral over [a, b] is the sum of c (b - clamp(t_c)).
  double sum = 0.0;
  mesh_crossings(triangles, o, v,
                 [&](double t, int c) { sum += c * (b - std::clamp(t, a, b)); });
  return std::clamp(sum, 0.0, b - a);
}

double MediumRegion::exit(const Vec3& o, const Vec3& v) const {
  double a = 0.0, b = std::numeric_limits<double>::infinity();
  clip(o, v, &a, &b);
  if (!(b > a)) return -1.0;
  if (shape != Shape::kMesh) return b;
  double last = -1.0;  // the last crossing of a closed surface is an exit
  mesh_crossings(triangles, o, v, [&](double t, int c) {
    if (c < 0 && t > last) last = t;
  });
  return last > 0.0 ? last : -1.0;
}

void MediumRegion::crossings(const Vec3& o, const Vec3& v, double t_end,
                             std::vector<double>* out) const {
  double a = 0.0, b = t_end;
  clip(o, v, &a, &b);  // a mesh: its bounds
  if (!(b > a)) return;
  if (shape != Shape::kMesh) {
    if (a > 0.0) out->push_back(a);
    if (b < t_end) out->push_back(b);
    return;
  }
  mesh_crossings(triangles, o, v, [&](double t, int) {
    if (t > 0.0 && t < t_end) out->push_back(t);
  });
}

namespace {

// Where o + t v (t >= 0) leaves the cube |x_i| <= kMediumExtent; 0 if o is outside it.
double extent_exit(const Vec3& o, const Vec3& v) {
  double t = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(std::abs(o[i]) <= kMediumExtent)) return 0.0;
    if (v[i] != 0.0) t = std::min(t, ((v[i] > 0.0 ? kMediumExtent : -kMediumExtent) - o[i]) / v[i]);
  }
  return t;
}

}  // namespace

double MediumField::free_path(const Vec3& o, const Vec3& v, double t_end, double tau) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  t_end = std::min(t_end, extent_exit(o, v));
  if (!(t_end > 0.0) || !(tau >= 0.0)) return kInf;
  if (regions_->empty()) {
    // Homogeneous: t = tau / sigma_t (the same numbers as delta tracking,
    // every tentative event of which is real here).
    const double sigma = global_ ? global_->sigma_t() : 0.0;
    if (!(sigma > 0.0)) return kInf;
    const double t = tau / sigma;
    return t < t_end ? t : kInf;
  }
  std::vector<double> cuts;
  for (const MediumRegion& r : *regions_) r.crossings(o, v, t_end, &cuts);
  cuts.push_back(t_end);
  std::sort(cuts.begin(), cuts.end());
  double t0 = 0.0;
  for (const double t1 : cuts) {
    if (!(t1 > t0)) continue;
    // Exact on [t0, t1], where the extinction is constant: depth / (t1 - t0).
    const double depth = optical_depth(o, v, t0, t1);
    if (depth > 0.0 && depth >= tau) return t0 + (t1 - t0) * (tau / depth);
    tau -= depth;
    t0 = t1;
  }
  return kInf;
}

double MediumField::last_exit(const Vec3& o, const Vec3& v) const {
  if (global_) return std::numeric_limits<double>::infinity();
  double t = -1.0;
  for (const MediumRegion& r : *regions_) t = std::max(t, r.exit(o, v));
  return t;
}

MediumField::MediumField(const Medium* global, const std::vector<MediumRegion>& regions)
    : global_(global), regions_(&regions) {
  majorant_ = global ? global->sigma_t() : 0.0;
  for (const MediumRegion& r : regions) majorant_ += r.sigma_t();
}

double MediumField::sigma_t(const Vec3& x) const {
  double s = global_ ? global_->sigma_t() : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) s += r.sigma_t();
  }
  return s;
}

double MediumField::sigma_s(const Vec3& x) const {
  double s = global_ ? global_->sigma_s : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) s += r.sigma_s;
  }
  return s;
}

double MediumField::k(const Vec3& x) const {
  double ss = global_ ? global_->sigma_s : 0.0;
  double sk = global_ ? global_->sigma_s * global_->k : 0.0;
  for (const MediumRegion& r : *regions_) {
    if (r.contains(x)) {
      ss += r.sigma_s;
      sk += r.sigma_s * r.k;
    }
  }
  return ss > 0.0 ? sk / ss : 0.0;
}

double MediumField::optical_depth(const Vec3& o, const Vec3& v, double t0, double t1) const {
  if (!(t1 > t0)) return 0.0;
  double tau = global_ ? global_->sigma_t() * (t1 - t0) : 0.0;
  for (const MediumRegion& r : *regions_) tau += r.sigma_t() * r.chord(o, v, t0, t1);
  return tau;
}

Medium parse_medium(const Node& n) {
  ObjectReader o(n, "a medium");
  o.allow_only(std::span<const std::string_view>(kMediumFields));
  Medium m;
  read_coefficients(o, &m);
  if (auto v = o.optional("beam_rule")) {
    m.beam_rule = read_enum<BeamMediumRule>(
        *v, {{"gauss2", BeamMediumRule::kGauss2}, {"midpoint", BeamMediumRule::kMidpoint}});
  }
  // Below 0.05 a piece of optical depth 1.6 already needs every one of the
  // kMaxBeamSubPieces; above 8 one sub-piece spans e^-8 of attenuation.
  if (auto v = o.optional("beam_step")) m.beam_step = check_closed(*v, read_number(*v), 0.05, 8.0);
  if (auto v = o.optional("estimator")) {
    m.estimator = read_enum<VolumeEstimator>(
        *v, {{"grid", VolumeEstimator::kGrid},
             {"beam", VolumeEstimator::kBeam},
             {"seed", VolumeEstimator::kSeed}});
  }
  if (auto v = o.optional("radius")) m.radius = check_closed(*v, read_number(*v), 0.0, 1e6);
  // At most 256: far past where the error stops falling (docs/media.md).
  if (auto v = o.optional("segments")) {
    m.segments =
        static_cast<int>(check_closed(*v, static_cast<double>(read_integer(*v)), 0.0, 256.0));
  }
  if (auto v = o.optional("radius_pixels")) {
    m.radius_pixels = check_closed(*v, read_number(*v), 0.0, 4096.0);
  }
  return m;
}

}  // namespace beamcast
