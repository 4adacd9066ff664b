// Direct light of a lit scene (pass "direct", gi.direct "shadow_maps"): each
// light is a few point emitters (DirectPoint in protocol/lights/light_base.hpp;
// with gi.direct_interleave 4, each pixel a quarter of an interleaved light's
// points, the rest from its neighbours in pass gi_resolve, direct_filter.glsl);
// a diffuse G-buffer point x with normal n (facing the camera) reflects
//   L = albedo / pi * sum_i flux_i * angular_i(c) * max(0, n.l) * V_i / d^2,
// V_i from point i's cube shadow map of the triangles (distance compared,
// bilinear percentage-closer filtering) and from shadow rays to the analytic
// occluders, times e^(-optical depth) to the point in a medium. Mirrors, glass, emitters and
// the background are left alone. Scenes without analytic occluders or a
// medium use the program "direct_light_lean" (prelude direct_lean_on.glsl):
// llvmpipe pays for the shadow-ray loop and the medium's branch even when
// never taken (12 of 73 ms at 512^2 on the Cornell box).
struct DirectPoint {
  vec4 position;  // xyz: relative to the direct anchor; w: mode (0 isotropic, 1 cosine, 2 cone)
  vec4 axis;      // xyz: unit axis; w: cos_outer
  vec4 flux;      // rgb: flux x scale; w: cos_inner
};
layout(std430, binding = 4) readonly buffer DirectPoints { DirectPoint points[]; };
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_gb_normal;
layout(binding = 2) uniform VIEW_SAMPLER u_gb_albedo;
layout(binding = 3) uniform samplerCubeArrayShadow u_shadows;
uniform vec3 u_point_offset;  // direct anchor minus eye
uniform int u_point_count;
uniform int u_interleaved;  // points [0, u_interleaved) are split over the 2 x 2 pattern (0: none)
uniform float u_far;    // shadow-map distances are stored over this
uniform float u_texel;  // a texel's angular size at a face centre (2 / size)
uniform float u_sigma_t;  // a medium's extinction: the light is attenuated on its way (0: none)

layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_split;  // direct_split (pass direct with the split target)

const float kPi = 3.14159265358979;

// True if an analytic occluder cuts the open segment o + t d, t in (0, len).
bool analytic_blocked(vec3 o, vec3 d, float len) {
  int first = view_index() * u_count;
  float lo = 1e-4 * len, hi = len * (1.0 - 1e-4);
  for (int i = 0; i < u_count; ++i) {
    AnalyticOccluder a = occ[first + i];
    if (a.b.w < 0.5) {
      float denom = dot(a.b.xyz, d);
      if (denom == 0.0) continue;
      float t = dot(a.a.xyz - o, a.b.xyz) / denom;
      if (t > lo && t < hi) return true;
    } else {
      vec3 to_c = a.a.xyz - o;
      float tc = dot(to_c, d);
      vec3 perp = to_c - tc * d;
      float h2 = a.a.w * a.a.w - dot(perp, perp);
      if (h2 < 0.0) continue;
      float h = sqrt(h2);
      if ((tc - h > lo && tc - h < hi) || (tc + h > lo && tc + h < hi)) return true;
    }
  }
  return false;
}

// What point i gives x (normal n): flux x angular x cos / d^2 x visibility
// (x transmittance), or zero.
vec3 point_light(int i, vec3 x, vec3 n) {
  DirectPoint p = points[i];
  vec3 to = p.position.xyz + u_point_offset - x;
  float d2 = dot(to, to);
  float dist = sqrt(d2);
  vec3 l = to / dist;
  float cos_x = dot(n, l);
  if (cos_x <= 0.0) return vec3(0.0);
  float c = -dot(p.axis.xyz, l);
  int mode = int(p.position.w + 0.5);
  float angular = 1.0;
  if (mode == 1) {
    angular = max(c, 0.0);
  } else if (mode == 2) {
    angular = c >= p.flux.w ? 1.0 : (c <= p.axis.w ? 0.0 : smoothstep(p.axis.w, p.flux.w, c));
  }
  if (angular <= 0.0) return vec3(0.0);
  // Slope-scaled lookup: x's own distance compared short by what its
  // surface's distance can change over the bilinear lookup's texels (half a
  // texel's footprint, and 1.5 footprints times tan of the light's angle to
  // the normal, capped at 64), so a lit surface does not shadow itself
  // (acne). Along the shadow ray, so the outlines and penumbrae stay where
  // they are (a normal offset, used until 2026-11-27, moved them by up to
  // 2 texels: test Gi.AShadowsOutlineStaysWhereTheOccluderPutsIt); light
  // leaks only within that distance of a contact.
  float foot = dist * u_texel;
  float tan_x = sqrt(max(0.0, 1.0 - cos_x * cos_x)) / cos_x;
  vec3 v = x - (p.position.xyz + u_point_offset);
  float short_by = foot * (0.5 + 1.5 * min(tan_x, 64.0));
  float visible = texture(u_shadows, vec4(v, float(i)), (dist - short_by) / u_far);
  if (visible <= 0.0) return vec3(0.0);
#ifdef BEAMCAST_DIRECT_LEAN
  return p.flux.rgb * (angular * cos_x * visible / d2);
#else
  if (u_count > 0 && analytic_blocked(x + (1e-4 * dist) * n, l, dist)) return vec3(0.0);
#ifdef BEAMCAST_MEDIUM_REGIONS
  float transmitted = exp(-(u_sigma_t * dist + region_depth(x, l, 0.0, dist)));
#else
  float transmitted = u_sigma_t > 0.0 ? exp(-u_sigma_t * dist) : 1.0;
#endif
  return p.flux.rgb * (angular * cos_x * visible * transmitted / d2);
#endif
}

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  float z = VIEW_TEXEL(u_view_depth, px).r;
  if (z >= 1e29) discard;  // no surface on this pixel
  vec4 albedo = VIEW_TEXEL(u_gb_albedo, px);
  if (albedo.w > 0.5) discard;  // mirrors, glass and emitters
  vec3 n = VIEW_TEXEL(u_gb_normal, px).xyz;
  vec3 x = view_point(gl_FragCoord.xy, z);
  // Interleaved points: this pixel's quarter (its place in the 2 x 2
  // pattern) at 4 times the weight, into direct_split for gi_resolve.
  vec3 split = vec3(0.0);
  for (int i = (px.x & 1) | ((px.y & 1) << 1); i < u_interleaved; i += 4) {
    split += point_light(i, x, n);
  }
  vec3 e = vec3(0.0);
  for (int i = u_interleaved; i < u_point_count; ++i) e += point_light(i, x, n);
  out_color = vec4(albedo.rgb / kPi * e, 0.0);
  out_split = vec4(4.0 * split, z);  // w: the view depth, > 0 (direct_filter.glsl)
}
