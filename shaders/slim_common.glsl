// SLIM support spheres as the GPU holds them (render/slim_pass.cpp packs
// them), and their local height field with the crease rule: shared by the
// point sampling (slim_points.vert) and the field evaluation
// (slim_accumulate.frag).
struct SlimGpu {
  vec4 center;  // xyz: relative to the scene's slim anchor; w: radius
  vec4 axis_u;  // the local frame in world space
  vec4 axis_v;
  vec4 axis_w;
  vec4 p1;      // A, B, C, D of w = A u^2 + B u v + C v^2 + D u + E v + F
  vec4 p2;      // E, F, crease (0 none, 1 min, 2 max), -
  vec4 q1;      // the second polynomial (creases)
  vec4 q2;
  vec4 albedo;  // rgb, material
};
layout(std430, binding = 5) readonly buffer SlimSpheres { SlimGpu spheres[]; };

// w = A u^2 + B u v + C v^2 + D u + E v + F and its gradient (df/du, df/dv).
float poly(vec4 a, vec4 b, vec2 x, out vec2 grad) {
  grad = vec2(2.0 * a.x * x.x + a.y * x.y + a.w, a.y * x.x + 2.0 * a.z * x.y + b.x);
  return a.x * x.x * x.x + a.y * x.x * x.y + a.z * x.y * x.y + a.w * x.x + b.x * x.y + b.y;
}

// f(u, v) with the crease rule, and the gradient of the polynomial it took.
float height(SlimGpu s, vec2 x, out vec2 grad) {
  float f = poly(s.p1, s.p2, x, grad);
  if (s.p2.z < 0.5) return f;
  vec2 g2;
  float f2 = poly(s.q1, s.q2, x, g2);
  bool second = s.p2.z < 1.5 ? f2 < f : f2 > f;
  if (second) {
    grad = g2;
    return f2;
  }
  return f;
}
