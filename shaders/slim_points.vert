// SLIM point sampling (seed 003; render/slim_pass.hpp): vertex k of sphere
// a_sphere's draw is one sample of its local height field. Its grid (m
// samples a side, up to s x s per cell for the second stage) was planned on
// the CPU for this view; points with zero weight and second-stage slots the
// cell does not need are moved out of the clip volume.
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
layout(std430, binding = 6) readonly buffer SlimGrids { uvec2 grids[]; };

layout(location = 0) in uint a_sphere;  // per instance: the draw's base instance
uniform vec3 u_offset;    // slim anchor minus eye
uniform int u_grid_base;  // this view's first grid

out float v_weight;
out float v_depth;  // view depth
out vec3 v_normal;  // world, outward (F grows along it)
flat out float v_radius;
flat out vec3 v_albedo;

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

vec3 surface(SlimGpu s, vec2 x) {
  vec2 g;
  float w = height(s, x, g);
  return s.center.xyz + x.x * s.axis_u.xyz + x.y * s.axis_v.xyz + w * s.axis_w.xyz + u_offset;
}

vec2 to_pixels(vec3 p) {
  vec4 c = cam.view_proj * vec4(p, 1.0);
  return (c.xy / max(c.w, 1e-30) * 0.5 + 0.5) * cam.viewport.xy;
}

void drop() {
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
  gl_PointSize = 1.0;
  v_weight = 0.0;
  v_depth = 0.0;
  v_normal = vec3(0.0);
  v_radius = 0.0;
  v_albedo = vec3(0.0);
}

void main() {
  select_view(view_index());
  SlimGpu s = spheres[a_sphere];
  uvec2 g = grids[u_grid_base + int(a_sphere)];
  uint m = max(g.x, 1u);
  uint fill = max(g.y, 1u);
  uint per_cell = fill * fill;
  uint cell = uint(gl_VertexID) / per_cell;
  uint sub = uint(gl_VertexID) % per_cell;
  float r = s.center.w;
  float h = 2.0 * r / float(m);
  vec2 x = vec2(-r) + (vec2(float(cell % m), float(cell / m)) + 0.5) * h;
  if (sub > 0u) {
    // The seed's second stage: as many samples a side as the cell's longer
    // projected diagonal (to the next samples in u and v) is over
    // sqrt(3)/2 pixels, from the projection's derivative at the cell's
    // first sample (cells are about a pixel: the linearization is close;
    // 5% margin).
    vec2 g0;
    float w0 = height(s, x, g0);
    vec3 p0 = s.center.xyz + x.x * s.axis_u.xyz + x.y * s.axis_v.xyz + w0 * s.axis_w.xyz + u_offset;
    vec4 c = cam.view_proj * vec4(p0, 1.0);
    vec4 cu = cam.view_proj * vec4(s.axis_u.xyz + g0.x * s.axis_w.xyz, 0.0);
    vec4 cv = cam.view_proj * vec4(s.axis_v.xyz + g0.y * s.axis_w.xyz, 0.0);
    float iw = 1.0 / max(c.w, 1e-30);
    vec2 du = 0.5 * cam.viewport.xy * (cu.xy - c.xy * (cu.w * iw)) * iw * h;
    vec2 dv = 0.5 * cam.viewport.xy * (cv.xy - c.xy * (cv.w * iw)) * iw * h;
    float diag = max(length(du + dv), length(du - dv));
    float level = min(ceil(1.05 * diag / 0.8660254), float(fill));
    float a = float(sub % fill), b = float(sub / fill);
    if (a >= level || b >= level) {
      drop();
      return;
    }
    x += vec2(a, b) * (h / level);
  }
  vec2 grad;
  float w = height(s, x, grad);
  float q2 = dot(vec3(x, w), vec3(x, w)) / (r * r);
  if (q2 >= 1.0) {
    drop();
    return;
  }
  float t = 1.0 - q2;
  v_weight = t * t * t;  // slim_weight (protocol/slim_model.hpp)
  vec3 p = s.center.xyz + x.x * s.axis_u.xyz + x.y * s.axis_v.xyz + w * s.axis_w.xyz + u_offset;
  v_normal = normalize(-grad.x * s.axis_u.xyz - grad.y * s.axis_v.xyz + s.axis_w.xyz);
  v_depth = dot(p, cam.cam_forward.xyz);
  v_radius = r;
  v_albedo = s.albedo.rgb;
  gl_Position = cam.view_proj * vec4(p, 1.0);
  gl_PointSize = 1.0;
}
