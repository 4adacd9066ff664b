// SLIM pass 3 (seed 003): the pixel's surface from the accumulated sums,
// written where the surface is seen: shaded colour and view depth
// (slim_resolve), or the G-buffer of a lit scene (slim_gbuffer, u_gi = 1)
// for the lighting passes; and (normal, view depth) into slim_surface.
// slim.evaluation "blend" (the seed's): the points' weighted mean normal
// and depth. "field": F's sums at two points of the centre ray, x1 at the
// nearest depth there (slim_centre) and x2 u_step pixel footprints behind; where sum w h
// changes sign between them or nearly (the zero within one step outside),
// the zero of its linear interpolation is the depth and the interpolated
// gradient the normal; else one Newton step of F from x1 and F's gradient
// there; the blend where no sphere's support holds x1.
layout(binding = 0) uniform VIEW_SAMPLER u_sum_normal;
layout(binding = 1) uniform VIEW_SAMPLER u_sum_albedo;
layout(binding = 2) uniform VIEW_SAMPLER u_sum_field;
layout(binding = 3) uniform VIEW_SAMPLER u_sum_weight;
layout(binding = 4) uniform VIEW_SAMPLER u_centre;
layout(binding = 5) uniform VIEW_SAMPLER u_sum_field2;
layout(binding = 6) uniform VIEW_SAMPLER u_sum_weight2;
uniform int u_gi;
uniform int u_field;
uniform float u_step;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;
layout(location = 2) out vec4 out_surface;
layout(location = 3) out vec4 out_normal;
layout(location = 4) out vec4 out_albedo;

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
  float depth = sa.w / sn.w;
  if (u_field == 1) {
    vec4 sw = VIEW_TEXEL(u_sum_weight, px);
    vec4 sw2 = VIEW_TEXEL(u_sum_weight2, px);
    vec4 sf = VIEW_TEXEL(u_sum_field, px);
    vec4 sf2 = VIEW_TEXEL(u_sum_field2, px);
    float near = VIEW_TEXEL(u_centre, px).r;
    float footprint = 2.0 * cam.cam_right.w / cam.viewport.y * (is_orthographic() ? 1.0 : near);
    float step = u_step * footprint;
    float lambda = sf.w / (sf.w - sf2.w);  // the zero of sum w h between x1 (0) and x2 (1)
    if (sw.w > 0.0 && sw2.w > 0.0 && sf.w != sf2.w && lambda > -1.0 && lambda < 2.0) {
      vec4 f = mix(sf, sf2, lambda);
      vec4 w = mix(sw, sw2, lambda);
      vec3 grad = f.xyz - (f.w / w.w) * w.xyz;
      if (w.w > 0.0 && dot(grad, grad) > 0.0) {
        n = normalize(grad);
        depth = near + lambda * step;
      }
    } else if (sw.w > 0.0) {
      float f = sf.w / sw.w;
      vec3 grad = (sf.xyz - f * sw.xyz) / sw.w;
      float glen = length(grad);
      if (glen > 0.0) {
        n = grad / glen;
        depth = near;
        // Newton along the ray (view depth z = ray distance * cos_axis), where
        // the ray is not within ~3 degrees of the tangent plane; the step is
        // at most 16 pixels' footprint.
        float slope = dot(grad, ray.dir);
        if (abs(slope) > 0.05 * glen) {
          depth = near + clamp(-f / slope * ray.cos_axis, -16.0 * footprint, 16.0 * footprint);
        }
      }
    }
  }
  out_view_depth = depth;
  out_surface = vec4(n, depth);
  if (u_gi == 1) {
    out_color = vec4(0.0);
    out_normal = vec4(dot(n, ray.dir) > 0.0 ? -n : n, 0.0);
    out_albedo = vec4(albedo, 0.0);  // diffuse (slim surfaces are diffuse)
    return;
  }
  out_color = vec4(lambert(albedo, n, ray.dir), 0.0);
  out_normal = vec4(0.0);
  out_albedo = vec4(0.0);
}
