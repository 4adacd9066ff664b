// A medium filling the scene (pass "medium", render/medium_pass.hpp): what
// the surfaces (and the background) sent to the eye is attenuated by
// e^(-optical depth), the scene-wide medium's sigma_t s (s the ray distance
// to the surface) plus the regions' (medium_regions.glsl); with no surface on the
// ray the background lies at infinity and nothing of it arrives. Drawn with
// hdr *= this (blend factors zero, source colour).
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth (huge: none)
uniform int u_has_surfaces;
uniform float u_sigma_t;

layout(location = 0) out vec4 out_transmittance;

void main() {
  select_view(view_index());
  ViewRay ray = view_ray(gl_FragCoord.xy);
  // No surface: view depth 1e30 (FrameTargets::kNoSurface), e^(-sigma 1e30) = 0.
  float z = u_has_surfaces != 0 ? VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r : 1e30;
  float t = z / ray.cos_axis;
  float transmittance = exp(-(u_sigma_t * t + region_depth(ray.origin, ray.dir, 0.0, t)));
  out_transmittance = vec4(vec3(transmittance), 1.0);
}
