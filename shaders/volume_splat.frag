// In-scattered light from the volume photons (pass "volume_photons",
// render/medium_pass.hpp). Each photon, stored where it scattered with the
// power it arrived with and its travel direction, adds to the pixel whose
// ray passes within the kernel radius r of it (medium.radius, or less near
// the camera with medium.radius_pixels)
//   p(mu) power K,   mu = dot(travel, -ray.dir) (gi/phase.hpp's convention),
// the light scattered towards the eye, with K the kernel's weight along the
// visible part of the ray [t0, t1] (near plane to nearest surface):
//   beam estimate (u_estimator 0): the sphere kernel 1 / (4/3 pi r^3)
//     integrated along the chord through it, clipped to [t0, t1] and
//     attenuated exactly: (e^(-s a) - e^(-s b)) / (s V), [a, b] the clipped chord;
//   the seed's (u_estimator 1): the whole photon at the ray's point nearest
//     to it, t_c, attenuated from there: e^(-s t_c) / (pi r^2), if t_c lies
//     in [t0, t1].
// Both integrate to the same over the image plane for a photon far from
// surfaces; they differ where the kernel meets a surface or the near plane.
// Regions of medium: their optical depth to t_c (seed) or a (beam) is
// exact, or with u_segments = S > 0 (medium.segments, the seed's section
// 5.7) taken at the centre of the one of S equal segments of [0, t1] that
// holds that point.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth (huge: none)
uniform int u_has_surfaces;
flat in float v_radius;  // the photon's kernel radius (photon_splat.vert)
uniform float u_sigma_t;  // the scene-wide medium's (regions: medium_regions.glsl)
uniform int u_estimator;
uniform int u_segments;

flat in vec3 v_center;  // camera-relative
flat in vec3 v_power;
flat in vec3 v_normal;  // the photon's travel direction
flat in vec2 v_extra;   // x: Schlick k at the photon; y: sigma_t at the photon

layout(location = 0) out vec4 out_color;

const float kPi = 3.14159265358979;

// The regions' optical depth from the eye to t on the view ray, or to the
// centre of t's segment of [0, t_end] (u_segments of them).
float regions_to(ViewRay ray, float t, float t_end) {
  if (u_segments > 0) {
    float step = t_end / float(u_segments);
    t = (min(floor(t / step), float(u_segments - 1)) + 0.5) * step;
  }
  return region_depth(ray.origin, ray.dir, 0.0, t);
}

void main() {
  select_view(view_index());
  ViewRay ray = view_ray(gl_FragCoord.xy);
  vec3 to_c = v_center - ray.origin;
  float tc = dot(to_c, ray.dir);
  vec3 perp = to_c - tc * ray.dir;
  float d2 = dot(perp, perp);
  float r2 = v_radius * v_radius;
  if (d2 >= r2) discard;
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    t1 = min(t1, VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r / ray.cos_axis);
  }
  float w;
  if (u_estimator == 1) {
    if (tc < t0 || tc > t1) discard;
    w = exp(-(u_sigma_t * tc + regions_to(ray, tc, t1))) / (kPi * r2);
  } else {
    float h = sqrt(r2 - d2);
    float a = max(tc - h, t0);
    float b = min(tc + h, t1);
    if (!(b > a)) discard;
    // Within the kernel the extinction is taken as the photon's own
    // (exact in a homogeneous medium).
    float x = v_extra.y * (b - a);
    // (e^(-s a) - e^(-s b)) / s = e^(-s a) (b - a) (1 - e^-x) / x; its series where x is small.
    float ratio = x < 1e-3 ? 1.0 - 0.5 * x : (1.0 - exp(-x)) / x;
    w = exp(-(u_sigma_t * a + regions_to(ray, a, t1))) * (b - a) * ratio /
        (4.0 / 3.0 * kPi * r2 * v_radius);
  }
  float k = v_extra.x;
  float mu = dot(v_normal, -ray.dir);
  float q = 1.0 - k * mu;
  float phase = (1.0 - k * k) / (4.0 * kPi * q * q);
  out_color = vec4(v_power * (phase * w), 0.0);
}
