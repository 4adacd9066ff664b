// SLIM support spheres as the GPU holds them (render/slim_pass.cpp packs
// them), their local height field with the crease rule, and the field
// evaluation's ownership rule: shared by the slim point programs.
struct SlimGpu {
  vec4 center;  // xyz: relative to the scene's slim anchor; w: radius
  vec4 axis_u;  // the local frame in world space
  vec4 axis_v;
  vec4 axis_w;
  vec4 p1;      // A, B, C, D of w = A u^2 + B u v + C v^2 + D u + E v + F
  vec4 p2;      // E, F, crease (0 none, 1 min, 2 max), atan(the largest slope)
  vec4 q1;      // the second polynomial (creases)
  vec4 q2;      // E, F, and the slab [lo, hi] of the patch's heights inside the sphere
  vec4 albedo;  // rgb, material
};
layout(std430, binding = 5) readonly buffer SlimSpheres { SlimGpu spheres[]; };

// w = A u^2 + B u v + C v^2 + D u + E v + F and its gradient (df/du, df/dv).
float poly(vec4 a, vec4 b, vec2 x, out vec2 grad) {
  grad = vec2(2.0 * a.x * x.x + a.y * x.y + a.w, a.y * x.x + 2.0 * a.z * x.y + b.x);
  return a.x * x.x * x.x + a.y * x.x * x.y + a.z * x.y * x.y + a.w * x.x + b.x * x.y + b.y;
}

// f(u, v) with the crease rule (crease = p2.z: 0 none, 1 min, 2 max of the
// polynomials (p1, p2) and (q1, q2)), and the gradient of the one it took.
float crease_height(vec4 p1, vec4 p2, vec4 q1, vec4 q2, vec2 x, out vec2 grad) {
  float f = poly(p1, p2, x, grad);
  if (p2.z < 0.5) return f;
  vec2 g2;
  float f2 = poly(q1, q2, x, g2);
  if (p2.z < 1.5 ? f2 < f : f2 > f) {
    grad = g2;
    return f2;
  }
  return f;
}

float height(SlimGpu s, vec2 x, out vec2 grad) { return crease_height(s.p1, s.p2, s.q1, s.q2, x, grad); }

// Field evaluation: where the centre ray `ray` meets the height field of
// sphere s (centre c, camera-relative), by Newton steps along the ray from
// the crossing of the sample's tangent plane (point p, unit normal n), and
// whether that point is the sample's own: inside the sphere and over the
// sample's (u, v) square (cell: corner, side). Neighbouring samples of a
// sphere converge to the same point, so exactly one of them owns it: each
// sphere answers once per pixel. t: the ray distance of the point.
bool slim_owner(SlimGpu s, vec3 c, ViewRay ray, vec3 p, vec3 n, vec3 cell, out float t) {
  t = 0.0;
  float dn = dot(ray.dir, n);
  if (abs(dn) < 1e-4) return false;
  t = dot(p - ray.origin, n) / dn;
  vec3 o = ray.origin - c;
  vec3 dl = vec3(dot(ray.dir, s.axis_u.xyz), dot(ray.dir, s.axis_v.xyz), dot(ray.dir, s.axis_w.xyz));
  vec3 ol = vec3(dot(o, s.axis_u.xyz), dot(o, s.axis_v.xyz), dot(o, s.axis_w.xyz));
  float r = s.center.w;
  // Cheap rejection first: the tangent plane's crossing lies within four
  // sides of the sample's square unless the ray grazes the patch (a
  // second-stage square is small against how far a curved patch's tangent
  // plane strays at a grazing pixel: a one-side window missed 2 pixels of
  // fandisk at S = 8).
  vec2 uv0 = (ol + t * dl).xy - cell.xy;
  if (any(lessThan(uv0, vec2(-4.0 * cell.z))) || any(greaterThan(uv0, vec2(5.0 * cell.z)))) return false;
  float h = 0.0;
  for (int k = 0; k < 4; ++k) {
    vec3 l = ol + t * dl;
    vec2 gf;
    h = l.z - height(s, l.xy, gf);
    float slope = dl.z - dot(gf, dl.xy);
    if (abs(slope) < 1e-4) return false;
    t -= h / slope;
  }
  vec3 l = ol + t * dl;
  vec2 gf;
  if (abs(l.z - height(s, l.xy, gf)) > 1e-4 * r) return false;  // did not settle
  if (dot(l, l) >= r * r) return false;
  vec2 uv = l.xy - cell.xy;
  return uv.x >= 0.0 && uv.x < cell.z && uv.y >= 0.0 && uv.y < cell.z;
}

// The field evaluation's step along the centre ray (view depth) from the
// nearest depth `near`: u_step pixel footprints, at most a twentieth of the
// smallest owning sphere's radius (F bends over the spheres' size: a
// linear interpolation of its sums over the step is then accurate to
// ~(1/20)^2 of it).
uniform float u_step;
float slim_field_step(float near, float radius) {
  float footprint = 2.0 * cam.cam_right.w / cam.viewport.y * (is_orthographic() ? 1.0 : near);
  return min(u_step * footprint, 0.05 * radius);
}
