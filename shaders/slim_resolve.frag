// SLIM pass 3 (seed 003): the weighted sums normalized by the sum of the
// weights, written where the surface is seen: shaded colour and view depth
// (slim_resolve), or the G-buffer of a lit scene (slim_gbuffer, u_gi = 1)
// for the lighting passes.
layout(binding = 0) uniform VIEW_SAMPLER u_sum_normal;
layout(binding = 1) uniform VIEW_SAMPLER u_sum_albedo;
uniform int u_gi;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_albedo;

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 sn = VIEW_TEXEL(u_sum_normal, px);
  if (!(sn.w > 0.0)) discard;
  vec4 sa = VIEW_TEXEL(u_sum_albedo, px);
  ViewRay ray = view_ray(vec2(px) + 0.5);
  float len = length(sn.xyz);
  vec3 n = len > 1e-6 * sn.w ? sn.xyz / len : -ray.dir;
  vec3 albedo = sa.rgb / sn.w;
  out_view_depth = sa.w / sn.w;
  if (u_gi == 1) {
    out_color = vec4(0.0);
    out_normal = vec4(dot(n, ray.dir) > 0.0 ? -n : n, 0.0);
    out_albedo = vec4(albedo, 0.0);  // diffuse (slim surfaces are diffuse)
    return;
  }
  out_color = vec4(lambert(albedo, n, ray.dir), 0.0);
}
