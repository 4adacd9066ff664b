// Quads and quad lights for the lit-scene tests (path tracer, specular
// shading), built in code as the parser would build them.
#pragma once

#include <numbers>

#include "protocol/scene.hpp"

namespace beamcast::test {

// A perspective camera (fov_y in degrees) with a far plane out of the way.
inline Camera make_camera(const Vec3& pos, const Vec3& target, double fov_y, int w, int h) {
  Camera c;
  c.position = pos;
  c.target = target;
  c.fov_y_deg = fov_y;
  c.width = w;
  c.height = h;
  c.far_plane = 1e4;
  return c;
}

inline Occluder quad_occluder(const Vec3& corner, const Vec3& eu, const Vec3& ev, Material m = {},
                              Color albedo = {0.8, 0.8, 0.8}) {
  Occluder o;
  o.shape = QuadOccluder{corner, eu, ev, true};
  o.albedo = albedo;
  o.material = m;
  return o;
}

// A quad light of radiance L (flux = pi A L, as the parser makes it).
inline Light quad_light(const Vec3& corner, const Vec3& eu, const Vec3& ev, const Color& L) {
  QuadLight q;
  q.corner = corner;
  q.edge_u = eu;
  q.edge_v = ev;
  const Vec3 n = cross(eu, ev);
  q.area = length(n);
  q.normal = (1.0 / q.area) * n;
  Light l;
  l.shape = q;
  l.flux = (std::numbers::pi * q.area) * L;
  return l;
}

// A mirror floor y = 0 facing up (reflectance `mirror`) and a quad light of
// radiance L centred at (2, 2, 0) facing back along (-1, -1, 0): a ray from
// (-2, 2, 0) to the origin reflects along (1, 1, 0) into the light.
inline Scene mirror_floor_and_light(const Color& L, const Color& reflectance) {
  Scene scene;
  Material mirror;
  mirror.type = MaterialType::kMirror;
  mirror.reflectance = reflectance;
  scene.occluders.push_back(
      quad_occluder({-10.0, 0.0, -10.0}, {0.0, 0.0, 20.0}, {20.0, 0.0, 0.0}, mirror));
  scene.lights.push_back(quad_light({1.5, 2.5, -1.0}, {1.0, -1.0, 0.0}, {0.0, 0.0, 2.0}, L));
  return scene;
}

// A glass slab z in [1, 1.1] (ior 1.5, tint `tint`), each face's normal
// pointing out of the glass, over a quad light of radiance L at z = 0
// facing +z (4 x 4, centred on the z axis).
inline Scene glass_slab_over_light(const Color& L, const Color& tint) {
  Scene scene;
  Material glass;
  glass.type = MaterialType::kGlass;
  glass.ior = 1.5;
  glass.tint = tint;
  scene.occluders.push_back(
      quad_occluder({-5.0, -5.0, 1.1}, {10.0, 0.0, 0.0}, {0.0, 10.0, 0.0}, glass));
  scene.occluders.push_back(
      quad_occluder({-5.0, -5.0, 1.0}, {0.0, 10.0, 0.0}, {10.0, 0.0, 0.0}, glass));
  scene.lights.push_back(quad_light({-2.0, -2.0, 0.0}, {4.0, 0.0, 0.0}, {0.0, 4.0, 0.0}, L));
  return scene;
}

}  // namespace beamcast::test
