// A photon's reflected radiance at the G-buffer's surface point x (seed 001,
// eq. 4.2): L += (albedo / pi) * power * w(|x - p|) with the kernel w
// normalized over the disk of radius r; this pass sums power * w / pi (the
// albedo is applied per pixel by gi_resolve, after upsampling). The photon's power is already what
// crossed the surface (cosine-weighted by the tracing): no n.l factor here.
// Photons do not light surfaces facing another way (normal test: a thin
// wall's other side) or off their plane (plane-distance test: a parallel
// surface within the radius).
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_gb_normal;
layout(binding = 2) uniform VIEW_SAMPLER u_gb_albedo;
uniform float u_radius;
// The kernel, SplatKernel: 0 box, 1 cone, 2 Epanechnikov (set by the
// programs' preludes, gi_kernel_*.glsl).
#ifndef GI_KERNEL
#define GI_KERNEL 2
#endif
uniform float u_min_cos;   // normal test: cos of the largest angle between the normals
uniform float u_max_plane; // plane test: largest distance off the surface's plane, x radius
// A band's texel plus u_band_shift is its splat-grid texel (render/pass_plan.hpp,
// SplatBands; the pass draws once per band).
uniform ivec2 u_band_shift;
uniform int u_splat_scale; // this target has 1/u_splat_scale of the G-buffer's pixels per side

flat in vec3 v_center;
flat in vec3 v_power;
flat in vec3 v_normal;

layout(location = 0) out vec4 out_color;

const float kPi = 3.14159265358979;

void main() {
  select_view(view_index());
  // The G-buffer pixel this (splat-size) pixel stands for (gi_resolve.frag
  // uses the same one).
  ivec2 px = min((ivec2(gl_FragCoord.xy) + u_band_shift) * u_splat_scale + u_splat_scale / 2,
                 ivec2(cam.viewport.xy) - 1);
  float z = VIEW_TEXEL(u_view_depth, px).r;
  if (z >= 1e29) discard;  // no surface on this pixel
  vec3 d = view_point(vec2(px) + 0.5, z) - v_center;
  float r2 = u_radius * u_radius;
  float d2 = dot(d, d);
  // The distance first: most of the quad's fragments end here, before the
  // normal and material fetches.
  if (d2 >= r2) discard;
  if (VIEW_TEXEL(u_gb_albedo, px).w > 0.5) discard;  // mirrors and glass store no photons
  vec3 n = VIEW_TEXEL(u_gb_normal, px).xyz;
  if (dot(n, v_normal) < u_min_cos) discard;
  if (abs(dot(d, n)) > u_max_plane * u_radius) discard;
#if GI_KERNEL == 0
  float w = 1.0 / (kPi * r2);
#elif GI_KERNEL == 1
  float w = 3.0 / (kPi * r2) * (1.0 - sqrt(d2 / r2));
#else
  float w = 2.0 / (kPi * r2) * (1.0 - d2 / r2);
#endif
  // Irradiance / pi: gi_resolve multiplies by the albedo of each pixel.
  out_color = vec4(v_power * (w / kPi), 0.0);
}
