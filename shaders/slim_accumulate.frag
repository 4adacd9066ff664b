// SLIM pass 2 (seed 003): the points within the depth threshold behind the
// pixel's nearest depth; the rest lie on a hidden part of the surface.
// slim.evaluation "blend" (the seed's, u_field = 0): every point in the
// pixel adds its weighted normal, albedo and depth. "field": the point
// that stands for its sphere at the pixel's centre ray (slim_owner) adds
// that sphere's terms of F and its gradient at a point x of the ray:
//   w h, w grad h + h grad w, grad w, w
// with h = (local w) - f(u, v) and w = (1 - |x - c|^2 / r^2)^3, so that the
// resolve pass gets F = sum w h / sum w and grad F exactly as the CPU
// reference (protocol/slim_model.hpp) defines them, over the spheres whose
// points reach the pixel.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_near;
layout(binding = 2) uniform VIEW_SAMPLER u_radius;
uniform float u_threshold;  // slim.depth_threshold, in units of the point's sphere radius
uniform int u_field;
uniform vec3 u_offset;  // slim anchor minus eye

in float v_weight;
in float v_depth;
in vec3 v_normal;
flat in float v_radius;
flat in vec3 v_albedo;
flat in uint v_sphere;
flat in vec3 v_point;
flat in vec2 v_window;
flat in vec3 v_cell;

layout(location = 0) out vec4 out_albedo;  // blend: (w albedo, w depth); field: (w(x1) albedo, 0)
layout(location = 1) out vec4 out_field;   // field: (w grad h + h grad w, w h) at x; blend: (w n, w)
layout(location = 2) out vec4 out_weight;  // (grad w, w) at x
layout(location = 3) out vec4 out_field2;  // the same at x2
layout(location = 4) out vec4 out_weight2;


// Sphere s's terms of F at x (relative to its centre): (w grad h + h grad w,
// w h) and (grad w, w); false (zeros) outside its support.
bool field_terms(SlimGpu s, vec3 x, out vec4 field, out vec4 weight) {
  field = vec4(0.0);
  weight = vec4(0.0);
  float r = s.center.w;
  float q = 1.0 - dot(x, x) / (r * r);
  if (q <= 0.0) return false;
  vec3 l = vec3(dot(x, s.axis_u.xyz), dot(x, s.axis_v.xyz), dot(x, s.axis_w.xyz));
  vec2 gf;
  float h = l.z - height(s, l.xy, gf);
  vec3 gh = s.axis_w.xyz - gf.x * s.axis_u.xyz - gf.y * s.axis_v.xyz;
  float w = q * q * q;
  vec3 gw = (-6.0 * q * q / (r * r)) * x;
  field = vec4(w * gh + h * gw, w * h);
  weight = vec4(gw, w);
  return true;
}

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  float near = VIEW_TEXEL(u_near, px).r;
  if (near >= 1e29) discard;  // nothing reaches this pixel: not covered
  out_albedo = vec4(0.0);
  out_field = vec4(0.0);
  out_weight = vec4(0.0);
  out_field2 = vec4(0.0);
  out_weight2 = vec4(0.0);
  if (u_field == 0) {
    if (v_depth >= VIEW_TEXEL(u_scene_depth, px).r) discard;
    if (v_depth > near + u_threshold * v_radius) discard;
    out_field = vec4(v_weight * v_normal, v_weight);  // blend: the normal sums
    out_albedo = vec4(v_weight * v_albedo, v_weight * v_depth);
    return;
  }
  SlimGpu s = spheres[v_sphere];
  vec3 c = s.center.xyz + u_offset;
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float t;
  if (!slim_owner(s, c, ray, v_point, v_normal, v_cell, t)) discard;
  float depth = t * ray.cos_axis;
  if (depth >= VIEW_TEXEL(u_scene_depth, px).r) discard;
  if (depth > near + u_threshold * v_radius) discard;  // a hidden layer
  // F's terms at two points of the ray: x1 at the nearest depth and x2 one
  // step behind it (slim_field_step; the resolve pass interpolates between
  // them to F's zero).
  vec3 x1 = ray.origin + ray.dir * (near / ray.cos_axis) - c;
  float step = slim_field_step(near, VIEW_TEXEL(u_radius, px).r);
  vec4 t1, t2, t3, t4;
  bool any = field_terms(s, x1, t1, t2);
  any = field_terms(s, x1 + ray.dir * (step / ray.cos_axis), t3, t4) || any;
  if (!any) discard;
  out_field = t1;
  out_weight = t2;
  out_field2 = t3;
  out_weight2 = t4;
  out_albedo = vec4(t2.w * v_albedo, 0.0);  // albedo blended by w at x1
}
