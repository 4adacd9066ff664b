#include "protocol/occluders/box.hpp"

#include <cmath>

#include "protocol/occluders/occluder_parse.hpp"

namespace beamcast {

namespace {

std::array<double, 4> unit(const std::array<double, 4>& r) {
  const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
  return {r[0] / n, r[1] / n, r[2] / n, r[3] / n};
}

}  // namespace

BoxOccluder BoxOccluder::parse(const OccluderParse& in) {
  in.allow({"center", "size", "rotation"});
  BoxOccluder b;
  b.center = json_read::read_point(in.fields.required("center"), in.limits());
  const json_read::Node size = in.fields.required("size");
  b.size = json_read::read_vec3(size);
  for (std::size_t i = 0; i < 3; ++i) {
    b.size[i] = json_read::read_size(
        json_read::Node{&size.json()[i], json_read::child_path(size.path, i)}, in.limits());
  }
  if (auto r = in.fields.optional("rotation")) b.rotation = json_read::read_quaternion(*r);
  return b;
}

std::array<Vec3, 8> BoxOccluder::corners() const {
  std::array<Vec3, 8> c;
  for (int i = 0; i < 8; ++i) {
    const Vec3 local{(i & 1 ? 0.5 : -0.5) * size[0], (i & 2 ? 0.5 : -0.5) * size[1],
                     (i & 4 ? 0.5 : -0.5) * size[2]};
    c[static_cast<std::size_t>(i)] = center + rotate(rotation, local);
  }
  return c;
}

Aabb BoxOccluder::bounds() const {
  Aabb box;
  for (const Vec3& p : corners()) box.grow(p);
  return box;
}

void BoxOccluder::gpu_triangles(TriangleSink& out) const {
  static const int kIndex[36] = {4, 6, 2, 4, 2, 0, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                                 6, 7, 3, 6, 3, 2, 2, 3, 1, 2, 1, 0, 4, 5, 7, 4, 7, 6};
  const std::array<Vec3, 8> c = corners();
  for (int t = 0; t < 12; ++t) {
    out.add(c[kIndex[3 * t]], c[kIndex[3 * t + 1]], c[kIndex[3 * t + 2]], false);
  }
}

std::optional<OccluderHit> BoxOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                  double t_max) const {
  const std::array<double, 4> q = unit(rotation);
  const std::array<double, 4> qc{q[0], -q[1], -q[2], -q[3]};
  const Vec3 ol = rotate(qc, o - center);
  const Vec3 vl = rotate(qc, v);
  const Vec3 half = 0.5 * size;
  double tn, tf;
  int an, af;
  if (!ray_box(ol, vl, Aabb{-1.0 * half, half}, &tn, &tf, &an, &af)) return std::nullopt;
  double t = 0.0;
  int axis = -1;
  if (tn >= t_min && tn <= t_max) {
    t = tn, axis = an;
  } else if (tf >= t_min && tf <= t_max) {  // ray starts inside the box
    t = tf, axis = af;
  }
  if (axis < 0) return std::nullopt;
  Vec3 nl{0.0, 0.0, 0.0};
  nl[static_cast<std::size_t>(axis)] = 1.0;
  return OccluderHit{t, rotate(q, nl)};
}

}  // namespace beamcast
