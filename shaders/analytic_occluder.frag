// Planes and spheres, ray-traced per pixel in one full-screen draw; the nearest
// hit writes colour, view depth and window depth, so the depth test merges it
// with the rasterized occluders.


layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;
// The G-buffer of lit scenes (pass "gbuffer"; ignored by "surfaces").
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_albedo;
uniform int u_gi;  // 1: G-buffer pass (no directional light)

void main() {
  select_view(view_index());
  int first = view_index() * u_count;
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float best = ray.t_max;
  int hit = -1;
  vec3 normal = vec3(0.0);
  for (int i = 0; i < u_count; ++i) {
    AnalyticOccluder o = occ[first + i];
    if (o.b.w < 0.5) {
      float denom = dot(o.b.xyz, ray.dir);
      if (denom == 0.0) continue;
      float t = dot(o.a.xyz - ray.origin, o.b.xyz) / denom;
      if (t >= ray.t_min && t < best) {
        best = t;
        hit = i;
        normal = o.b.xyz;
      }
    } else {
      vec3 to_c = o.a.xyz - ray.origin;
      float tc = dot(to_c, ray.dir);
      vec3 perp = to_c - tc * ray.dir;
      float h2 = o.a.w * o.a.w - dot(perp, perp);
      if (h2 < 0.0) continue;
      float h = sqrt(h2);
      float t = tc - h >= ray.t_min ? tc - h : tc + h;
      if (t >= ray.t_min && t < best) {
        best = t;
        hit = i;
        normal = normalize(ray.origin + t * ray.dir - o.a.xyz);
      }
    }
  }
  if (hit < 0) discard;
  float z = best * ray.cos_axis;
  if (u_gi == 1) {
    out_color = vec4(0.0);
    out_normal = vec4(dot(normal, ray.dir) > 0.0 ? -normal : normal, 0.0);
    out_albedo = occ[first + hit].albedo;
  } else {
    out_color = vec4(lambert(occ[first + hit].albedo.rgb, normal, ray.dir), 0.0);
  }
  out_view_depth = z;
  gl_FragDepth = window_depth(z);
}
