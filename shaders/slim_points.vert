// SLIM point sampling (seed 003; render/slim_pass.hpp): vertex k of sphere
// a_sphere's draw is one sample of its local height field. Its grid (m
// samples a side, up to s x s per cell for the second stage) was planned on
// the CPU for this view; points with zero weight and second-stage slots the
// cell does not need are moved out of the clip volume.
layout(std430, binding = 6) readonly buffer SlimGrids { uvec2 grids[]; };

layout(location = 0) in uint a_sphere;  // per instance: the draw's base instance
uniform vec3 u_offset;    // slim anchor minus eye
uniform int u_grid_base;  // this view's first grid
uniform int u_field;      // slim.evaluation "field": points as wide as their cells (below)
uniform float u_cell_diag;  // the second stage's largest projected cell diagonal (pixels)

out float v_weight;
out float v_depth;  // view depth
out vec3 v_normal;  // world, outward (F grows along it)
flat out float v_radius;
flat out vec3 v_albedo;
flat out uint v_sphere;
flat out vec3 v_point;   // the sample, camera-relative
flat out vec2 v_window;  // the sample's window position
flat out vec3 v_cell;    // the (u, v) square the sample stands for: corner, side

void drop() {
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
  gl_PointSize = 1.0;
  v_weight = 0.0;
  v_depth = 0.0;
  v_normal = vec3(0.0);
  v_radius = 0.0;
  v_albedo = vec3(0.0);
  v_sphere = 0u;
  v_point = vec3(0.0);
  v_window = vec2(0.0);
  v_cell = vec3(0.0);
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
  vec2 corner = vec2(-r) + vec2(float(cell % m), float(cell / m)) * h;
  // The cell's projected diagonals (to the next samples in u and v), from
  // the projection's derivative at the cell's centre (cells are about a
  // pixel: the linearization is close).
  vec2 xc = corner + 0.5 * h;
  vec2 g0;
  float w0 = height(s, xc, g0);
  vec3 p0 = s.center.xyz + xc.x * s.axis_u.xyz + xc.y * s.axis_v.xyz + w0 * s.axis_w.xyz + u_offset;
  vec4 c = cam.view_proj * vec4(p0, 1.0);
  vec4 cu = cam.view_proj * vec4(s.axis_u.xyz + g0.x * s.axis_w.xyz, 0.0);
  vec4 cv = cam.view_proj * vec4(s.axis_v.xyz + g0.y * s.axis_w.xyz, 0.0);
  float iw = 1.0 / max(c.w, 1e-30);
  vec2 du = 0.5 * cam.viewport.xy * (cu.xy - c.xy * (cu.w * iw)) * iw * h;
  vec2 dv = 0.5 * cam.viewport.xy * (cv.xy - c.xy * (cv.w * iw)) * iw * h;
  float diag = max(length(du + dv), length(du - dv));
  // The seed's second stage: L x L samples at the centres of L x L
  // sub-cells, L = the cell's longer projected diagonal over u_cell_diag
  // (5% margin), at most the s planned on the CPU. Blend: sqrt(3)/2 pixels,
  // so every pixel centre within a patch has a sample in its pixel; field:
  // 6 pixels, a bound on the points' size.
  float level = fill > 1u ? clamp(ceil(1.05 * diag / u_cell_diag), 1.0, float(fill)) : 1.0;
  float a = float(sub % fill), b = float(sub / fill);
  if (a >= level || b >= level) {
    drop();
    return;
  }
  float side = h / level;
  vec2 lo = corner + vec2(a, b) * side;
  vec2 x = lo + 0.5 * side;
  vec2 grad;
  float w = height(s, x, grad);
  float q2 = dot(vec3(x, w), vec3(x, w)) / (r * r);
  // Blend: a point outside the sphere weighs nothing. Field: a sample
  // stands for its whole square, kept while the square reaches into the
  // sphere's disc (slim_owner tests the exact crossing).
  vec2 nearest = clamp(vec2(0.0), lo, lo + side);
  if (u_field == 1 ? dot(nearest, nearest) >= r * r : q2 >= 1.0) {
    drop();
    return;
  }
  float t = max(1.0 - q2, 0.0);
  v_weight = t * t * t;  // slim_weight (protocol/slim_model.hpp)
  vec3 p = s.center.xyz + x.x * s.axis_u.xyz + x.y * s.axis_v.xyz + w * s.axis_w.xyz + u_offset;
  v_normal = normalize(-grad.x * s.axis_u.xyz - grad.y * s.axis_v.xyz + s.axis_w.xyz);
  v_depth = dot(p, cam.cam_forward.xyz);
  v_radius = r;
  v_albedo = s.albedo.rgb;
  v_sphere = a_sphere;
  v_point = p;
  v_cell = vec3(lo, side);
  gl_Position = cam.view_proj * vec4(p, 1.0);
  v_window = (gl_Position.xy / max(gl_Position.w, 1e-30) * 0.5 + 0.5) * cam.viewport.xy;
  // Field evaluation: the sample whose (u, v) square holds the point where
  // a pixel's centre ray meets the sphere's surface stands for the sphere
  // there (slim_common.glsl, slim_owner); that point projects within half
  // the square's diagonal of the sample, so a point that wide (a point
  // covers the pixels whose centres lie within half its size of it; 10%
  // margin for the linearization) reaches the pixel. Blend: single pixels.
  if (u_field == 0) {
    gl_PointSize = 1.0;
    return;
  }
  float size = ceil(1.1 * diag / level + 0.1);
  // A point whose centre lies outside the viewport is clipped whole: one
  // within reach of it is moved to its edge and widened by as much.
  vec2 inside = clamp(v_window, vec2(0.5), cam.viewport.xy - 0.5);
  float shift = max(abs(v_window.x - inside.x), abs(v_window.y - inside.y));
  if (shift > 0.0) {
    if (shift >= 0.5 * size || gl_Position.w <= 0.0) {
      drop();
      return;
    }
    size = ceil(size + 2.0 * shift);
    gl_Position.xy = (inside / cam.viewport.xy * 2.0 - 1.0) * gl_Position.w;
  }
  gl_PointSize = min(size, 32.0);
}
