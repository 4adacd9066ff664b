// The grid estimate's gather (pass "volume_grid", render/volume_grid.hpp):
// each pixel's view ray, over its visible part [near plane, nearest
// surface] within the grid's box (half a cell wider each side: the border
// cells' trilinear tails), marched in steps of half a cell, each step
// adding the grid's value G at its middle (trilinear: sum p(mu) power /
// volume, binned this frame by volume_grid_bin.comp) times the step's
// exact attenuation with the optical depth tau linear over the step:
//   G(t_mid) e^(-tau_a) dt (1 - e^(-dtau)) / dtau,
// tau the scene-wide medium's sigma_t t plus the regions' chords
// (medium_regions.glsl). Ends where the transmittance is below 1e-6.
// gi.lod: at distance D the share Q of the detail dropped reads level
// log2(1 / (1 - Q)) (capped at the coarsest) with steps 2^level as long.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth (huge: none)
layout(binding = 1) uniform sampler3D u_grid;
uniform int u_has_surfaces;
uniform float u_sigma_t;      // the scene-wide medium's (regions: medium_regions.glsl)
uniform vec3 u_grid_offset;   // grid origin minus eye
uniform vec3 u_grid_size;     // its world extent
uniform float u_cell;
uniform int u_lod;
uniform float u_lod_near;
uniform float u_lod_far;
uniform float u_max_level;

layout(location = 0) out vec4 out_color;

// At most this many steps a ray (4096 half cells: 2048 cells, past the
// grid's longest diagonal).
const int kMaxSteps = 4096;

float lod_level(float d) {
  if (u_lod == 0) return 0.0;
  float q = u_lod_near < u_lod_far ? smoothstep(u_lod_near, u_lod_far, d)
                                   : 1.0 - smoothstep(u_lod_far, u_lod_near, d);
  return min(-log2(max(1.0 - q, 1e-6)), u_max_level);
}

void main() {
  select_view(view_index());
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    t1 = min(t1, VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r / ray.cos_axis);
  }
  // The box, half a cell wider each side (slabs; a zero direction
  // component gives +-inf, which min/max order correctly).
  vec3 lo = u_grid_offset - 0.5 * u_cell - ray.origin;
  vec3 hi = u_grid_offset + u_grid_size + 0.5 * u_cell - ray.origin;
  vec3 inv = 1.0 / ray.dir;
  vec3 ta = lo * inv, tb = hi * inv;
  vec3 tn = min(ta, tb), tf = max(ta, tb);
  // 0 * inf (origin on a slab's plane, parallel to it) is NaN: that slab
  // does not bound the ray.
  tn = mix(tn, vec3(-1e30), isnan(tn));
  tf = mix(tf, vec3(1e30), isnan(tf));
  t0 = max(t0, max(tn.x, max(tn.y, tn.z)));
  t1 = min(t1, min(tf.x, min(tf.y, tf.z)));
  if (!(t1 > t0)) discard;
  float base = 0.5 * u_cell;
  float tau_a = u_sigma_t * t0 + region_depth(ray.origin, ray.dir, 0.0, t0);
  vec3 sum = vec3(0.0);
  float a = t0;
  for (int i = 0; i < kMaxSteps && a < t1; ++i) {
    float level = lod_level(length(ray.origin + a * ray.dir));
    float b = min(a + base * exp2(level), t1);
    float dt = b - a;
    float tau_b = u_sigma_t * b + region_depth(ray.origin, ray.dir, 0.0, b);
    float x = max(tau_b - tau_a, 0.0);
    // (1 - e^-x) / x; its series where x is small.
    float ratio = x < 1e-3 ? 1.0 - 0.5 * x : (1.0 - exp(-x)) / x;
    vec3 p = ray.origin + (0.5 * (a + b)) * ray.dir;
    vec3 g = textureLod(u_grid, (p - u_grid_offset) / u_grid_size, level).rgb;
    sum += g * (exp(-tau_a) * dt * ratio);
    tau_a = tau_b;
    a = b;
    if (tau_a > 14.0) break;  // e^-14 < 1e-6 of what follows remains
  }
  out_color = vec4(sum, 0.0);
}
