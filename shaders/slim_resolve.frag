// SLIM pass 3 (seed 003): the pixel's surface from the accumulated sums,
// written where the surface is seen: shaded colour and view depth
// (slim_resolve), or the G-buffer of a lit scene (slim_gbuffer, u_gi = 1)
// for the lighting passes; and (normal, view depth) into slim_surface.
// slim.evaluation "blend" (the seed's): the points' weighted mean normal
// and depth. "field": F's sums at two points of the centre ray, x1 at the
// nearest depth (slim_near: where the ray meets the nearest patch) and x2
// u_step pixel footprints behind; where F = sum w h / sum w changes sign
// between them or nearly (its zero within one step outside), the zero of
// its linear interpolation is the depth and the sums interpolated there
// give the normal; else x1 and F's gradient there.
layout(binding = 1) uniform VIEW_SAMPLER u_sum_albedo;
layout(binding = 2) uniform VIEW_SAMPLER u_sum_field;
layout(binding = 3) uniform VIEW_SAMPLER u_sum_weight;
layout(binding = 4) uniform VIEW_SAMPLER u_near;
layout(binding = 5) uniform VIEW_SAMPLER u_sum_field2;
layout(binding = 6) uniform VIEW_SAMPLER u_sum_weight2;
layout(binding = 7) uniform VIEW_SAMPLER u_radius;
uniform int u_gi;
uniform int u_field;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;
layout(location = 2) out vec4 out_surface;
layout(location = 3) out vec4 out_normal;
layout(location = 4) out vec4 out_albedo;

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  // The field's coverage test first: one fetch where nothing was drawn.
  vec4 sw = VIEW_TEXEL(u_sum_weight, px);
  if (u_field == 1 && !(sw.w > 0.0)) discard;
  vec4 sa = VIEW_TEXEL(u_sum_albedo, px);
  ViewRay ray = view_ray(vec2(px) + 0.5);
  vec3 n;
  vec3 albedo;
  float depth;
  if (u_field == 0) {
    vec4 sn = VIEW_TEXEL(u_sum_field, px);  // the blend's (w n, w)
    if (!(sn.w > 0.0)) discard;
    float len = length(sn.xyz);
    n = len > 1e-6 * sn.w ? sn.xyz / len : -ray.dir;
    albedo = sa.rgb / sn.w;
    depth = sa.w / sn.w;
  } else {
    // Covered where the centre ray meets a sphere's patch at x1 inside
    // some support (tested above: sw.w > 0).
    albedo = sa.rgb / sw.w;
    vec4 sw2 = VIEW_TEXEL(u_sum_weight2, px);
    vec4 sf = VIEW_TEXEL(u_sum_field, px);
    vec4 sf2 = VIEW_TEXEL(u_sum_field2, px);
    float near = VIEW_TEXEL(u_near, px).r;
    float radius = VIEW_TEXEL(u_radius, px).r;
    float step = slim_field_step(near, radius);
    // The zero of F = sum w h / sum w, linearly interpolated between x1 (0)
    // and x2 (1). (Interpolating sum w h instead misplaces it where the
    // weights change fast, at a support's rim: by up to a step.)
    float f1 = sf.w / sw.w, f2 = sw2.w > 0.0 ? sf2.w / sw2.w : f1;
    float lambda = f1 / (f1 - f2);
    vec4 f = sf;
    vec4 w = sw;
    depth = near;
    // The zero is taken within one step outside [x1, x2], or, where the
    // step is shorter than that bound, up to a tenth of the radius away.
    float reach = max(1.0, 0.1 * radius / step);
    if (sw2.w > 0.0 && f1 != f2 && lambda > -reach && lambda < 1.0 + reach) {
      f = mix(sf, sf2, lambda);
      w = mix(sw, sw2, lambda);
      depth = near + lambda * step;
      // Across a crease F's gradient jumps between x1 and x2 (the min/max
      // of two polynomials): there the nearer end's gradient, not a blend.
      vec3 g1 = sf.xyz - (sf.w / sw.w) * sw.xyz;
      vec3 g2 = sf2.xyz - (sf2.w / sw2.w) * sw2.xyz;
      if (dot(g1, g2) < 0.985 * length(g1) * length(g2)) {  // over 10 degrees apart
        f = lambda < 0.5 ? sf : sf2;
        w = lambda < 0.5 ? sw : sw2;
      }
    }
    if (!(w.w > 0.0)) {
      f = sf;
      w = sw;
      depth = near;
    }
    vec3 grad = f.xyz - (f.w / w.w) * w.xyz;
    float glen = length(grad);
    n = glen > 0.0 ? grad / glen : -ray.dir;
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
