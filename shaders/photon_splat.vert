// One camera-facing quad per photon (seed 001, section 4.2), covering every
// pixel whose surface point can lie within the radius of the photon: the
// projection of the sphere of that radius about it.
struct PhotonData {
  vec4 position;  // xyz: relative to the photon anchor; w: 1 if straight from the light
  vec4 power;     // rgb: flux (W per channel)
  vec4 normal;    // xyz: the normal of the surface it hit, facing where it came from
};
layout(std430, binding = 3) readonly buffer Photons { PhotonData photons[]; };
uniform vec3 u_photon_offset;  // photon anchor minus eye
uniform float u_radius;
uniform float u_power_scale;  // 1 / the share of the maps drawn (gi.display_fraction)
// The splat grid's bands (render/pass_plan.hpp, SplatBands): with
// u_band_cull 1 a disk whose quad lies wholly above or below the rows of
// this draw's band, u_band_ndc (NDC y, a pixel wider each side), is dropped
// before setup: llvmpipe pays ~1 us a disk a band in triangle setup and
// binning, the scissor rejecting it only after that. 0 (volume photons):
// no bands.
uniform int u_band_cull;
uniform vec2 u_band_ndc;

// Level of detail (seed 001, section 6; GiSettings::lod_*): 0 groups: off.
uniform int u_lod_groups;
uniform float u_lod_near;
uniform float u_lod_far;

flat out vec3 v_center;  // camera-relative
flat out vec3 v_power;
flat out vec3 v_normal;
#ifdef BEAMCAST_VOLUME_PHOTONS
// Volume photons only (program "volume_splat", prelude volume_photons_on.glsl;
// the surface photons' program stays without these outputs, which cost
// llvmpipe ~5% of a lit frame):
flat out vec2 v_extra;    // position.w and normal.w: the local k and sigma_t
flat out float v_radius;  // the kernel radius (u_radius, capped by u_radius_pixels)
// medium.radius_pixels: the kernel's radius on screen at most this many
// pixels (0: no cap).
uniform float u_radius_pixels;
#endif

// The LOD weight of photon `index` at camera-relative position c: the share
// Q of the groups dropped at its distance (smoothstep(near, far, D), or
// 1 - smoothstep(far, near, D) when near > far), group g = index mod A kept
// whole while g / A >= Q, fading out over the next 1 / A, the kept ones
// scaled by 1 / (1 - Q): the expected flux stays.
float lod_weight(vec3 c, int index) {
  if (u_lod_groups <= 0) return 1.0;
  float d = length(c);
  float q = u_lod_near < u_lod_far ? smoothstep(u_lod_near, u_lod_far, d)
                                   : 1.0 - smoothstep(u_lod_far, u_lod_near, d);
  if (q >= 1.0) return 0.0;
  float a = float(u_lod_groups);
  float kept = clamp((float(index % u_lod_groups) + 1.0) - q * a, 0.0, 1.0);
  return kept / (1.0 - q);
}

void main() {
  select_view(view_index());
  int index = gl_VertexID >> 2;  // quad `index` (QuadIndices, render/gl_util.hpp)
  PhotonData p = photons[index];
  vec3 c = p.position.xyz + u_photon_offset;
  v_center = c;
#ifdef BEAMCAST_VOLUME_PHOTONS
  v_extra = vec2(p.position.w, p.normal.w);
#endif
  float lod = lod_weight(c, index);
  if (lod <= 0.0) {  // dropped: a degenerate quad outside the clip volume
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_power = vec3(0.0);
    v_normal = vec3(0.0);
    return;
  }
  v_power = p.power.rgb * (u_power_scale * lod);
  v_normal = p.normal.xyz;
  // Corner (-1,-1) (1,-1) (-1,1) (1,1) of the quad (llvmpipe shades the
  // vertices on one thread: 4 a quad, not 6).
  vec2 k = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0);
  // Perspective: a sphere of radius r at distance D subtends asin(r / D); a
  // quad in its centre's plane facing the camera covers that cone with half
  // size r D / sqrt(D^2 - r^2) (here along the view axis, the worst case
  // for screen-aligned axes is within the same bound for the pixels it needs).
  float radius = u_radius;
#ifdef BEAMCAST_VOLUME_PHOTONS
  if (u_radius_pixels > 0.0) {
    // World size of a pixel at the photon's view depth.
    float half_height = is_orthographic() ? cam.cam_right.w
                                          : max(dot(c, cam.cam_forward.xyz), 0.0) * cam.cam_right.w;
    radius = min(radius, max(u_radius_pixels * 2.0 * half_height / cam.viewport.y, 1e-6 * radius));
  }
  v_radius = radius;
#endif
  float s = radius;
  if (!is_orthographic()) {
    float d2 = dot(c, c);
    s = radius * sqrt(d2 / max(d2 - radius * radius, 0.01 * d2));
  }
  vec4 centre = cam.view_proj * vec4(c, 1.0);
  vec4 across = cam.view_proj * vec4(s * cam.cam_right.xyz, 0.0);
  vec4 up = cam.view_proj * vec4(s * cam.cam_up.xyz, 0.0);
  if (u_band_cull != 0 && centre.w > 0.0) {
    // The quad lies in the plane through c parallel to the image (right
    // and up are across the view axis): its corners share centre.w.
    float half_y = (abs(across.y) + abs(up.y)) / centre.w;
    float y = centre.y / centre.w;
    if (y + half_y < u_band_ndc.x || y - half_y > u_band_ndc.y) {
      gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the clip volume
      v_power = vec3(0.0);
      return;
    }
  }
  gl_Position = centre + k.x * across + k.y * up;
}
