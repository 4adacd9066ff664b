// SLIM pass 2 (seed 003): the points within the depth threshold behind the
// pixel's nearest point; the rest lie on a hidden part of the surface.
// Every point whose sample lies in the pixel adds its weighted normal,
// albedo and depth (the seed's blend). With slim.evaluation "field"
// (u_field = 1) the point that stands for its sphere at the pixel's centre
// ray also adds that sphere's terms of F and its gradient at the ray's
// point x at the nearest depth (slim_centre: at the centre ray):
//   w h, w grad h + h grad w, grad w, w
// with h = (local w) - f(u, v) and w = (1 - |x - c|^2 / r^2)^3, so that the
// resolve pass gets F = sum w h / sum w and grad F exactly as the CPU
// reference (protocol/slim_model.hpp) defines them, over the spheres whose
// points reach the pixel.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_near;
layout(binding = 2) uniform VIEW_SAMPLER u_centre;
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

layout(location = 0) out vec4 out_normal;  // (w n, w) of the points in the pixel
layout(location = 1) out vec4 out_albedo;  // (w albedo, w depth)
layout(location = 2) out vec4 out_field;   // (w grad h + h grad w, w h) at x
layout(location = 3) out vec4 out_weight;  // (grad w, w) at x
layout(location = 4) out vec4 out_field2;  // the same at x2
layout(location = 5) out vec4 out_weight2;

uniform float u_step;

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
  if (near >= 1e29) discard;  // no point in this pixel: not covered
  if (v_depth >= VIEW_TEXEL(u_scene_depth, px).r) discard;
  if (v_depth > near + u_threshold * v_radius) discard;
  out_normal = vec4(0.0);
  out_albedo = vec4(0.0);
  out_field = vec4(0.0);
  out_weight = vec4(0.0);
  out_field2 = vec4(0.0);
  out_weight2 = vec4(0.0);
  bool any = false;
  vec2 off = v_window - gl_FragCoord.xy;
  if (u_field == 0 || (off.x >= -0.5 && off.x < 0.5 && off.y >= -0.5 && off.y < 0.5)) {
    out_normal = vec4(v_weight * v_normal, v_weight);
    out_albedo = vec4(v_weight * v_albedo, v_weight * v_depth);
    any = true;
  }
  if (u_field == 1) {
    SlimGpu s = spheres[v_sphere];
    vec3 c = s.center.xyz + u_offset;
    ViewRay ray = view_ray(gl_FragCoord.xy);
    // Which sample stands for the sphere here: the one whose (u, v) square
    // holds the ray's crossing of its tangent plane (neighbouring samples'
    // planes agree to second order, so one sample of the sphere answers).
    float dn = dot(ray.dir, v_normal);
    if (abs(dn) > 1e-6) {
      vec3 hit = ray.origin + ray.dir * (dot(v_point - ray.origin, v_normal) / dn) - c;
      vec2 uv = vec2(dot(hit, s.axis_u.xyz), dot(hit, s.axis_v.xyz)) - v_cell.xy;
      if (uv.x >= 0.0 && uv.x < v_cell.z && uv.y >= 0.0 && uv.y < v_cell.z) {
        // F's terms at two points of the ray: x1 at the nearest depth (at
        // the centre) and x2
        // u_step pixel footprints behind it (the resolve pass interpolates
        // between them to F's zero).
        float centre = VIEW_TEXEL(u_centre, px).r;
        vec3 x1 = ray.origin + ray.dir * (centre / ray.cos_axis) - c;
        float step = u_step * 2.0 * cam.cam_right.w / cam.viewport.y * (is_orthographic() ? 1.0 : centre);
        vec4 t1, t2, t3, t4;
        any = field_terms(s, x1, t1, t2) || any;
        any = field_terms(s, x1 + ray.dir * (step / ray.cos_axis), t3, t4) || any;
        out_field = t1;
        out_weight = t2;
        out_field2 = t3;
        out_weight2 = t4;
      }
    }
  }
  if (!any) discard;
}
