// Scalar volume ray casting (pass "volumes", render/volume_pass.hpp; seed 004,
// docs/volumes.md). The pixel's centre ray is clipped to the volume's box
// (grid coordinates [0, n - 1]^3, protocol/volume.hpp) and to the nearest
// surface, then marched front to back in steps of u_step: one trilinear
// sample per step (at a per-pixel jittered fraction of it, or its middle),
// its transfer function's colour and opacity, the opacity corrected for the
// segment's length, alpha = 1 - (1 - opacity)^(length / opacity unit), or
// the seed's fixed exponent; stops once the opacity reaches u_ert. Written
// as (colour, opacity) and blended hdr = colour + (1 - opacity) hdr; the
// transmittance at the knots of volume_knots.glsl (multiplied into
// volume_t0/volume_t1 over the volumes) for the beams.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth
layout(binding = 1) uniform sampler3D u_values;         // normalized values, GL_R16
layout(binding = 2) uniform sampler1D u_transfer;       // (colour x intensity, log2(1 - opacity))
layout(binding = 3) uniform usampler3D u_bricks;        // 1: the brick can show something
uniform int u_has_surfaces;
uniform mat3 u_rotation;  // world from (grid x spacing)
uniform vec3 u_origin;    // voxel (0, 0, 0)'s centre, relative to the eye
uniform vec3 u_spacing;
uniform vec3 u_dims;
uniform float u_step;
uniform float u_opacity_unit;
uniform float u_fixed_exponent;  // < 0: opacity correction; else every sample's exponent
uniform float u_ert;
uniform int u_jitter;
uniform int u_skip_empty;
uniform int u_knots;  // 0: no beams read the knots (none are tracked)

layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_knots0;  // knots 0-3
layout(location = 2) out vec4 out_knots1;  // knots 4-7

const float kTransferTexels = 1024.0;  // render/volume_pass.hpp kTransferTexels
const float kBrickCells = 8.0;         // render/volume_pass.hpp kBrickCells

// Interleaved gradient noise: a per-pixel offset in [0, 1), the same every
// frame (frames stay reproducible, bit for bit, on any server).
float pixel_jitter(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main() {
  select_view(view_index());
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    t1 = min(t1, VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r / ray.cos_axis);
  }
  float knot_a, knot_b;
  bool knots = volume_knot_interval(ray, t1, knot_a, knot_b);
  // The ray in grid coordinates, g(t) = og + t dg (t the world ray distance).
  mat3 to_grid = transpose(u_rotation);
  vec3 og = (to_grid * (ray.origin - u_origin)) / u_spacing;
  vec3 dg = (to_grid * ray.dir) / u_spacing;
  vec3 hi = u_dims - 1.0;
  for (int a = 0; a < 3; ++a) {
    if (abs(dg[a]) < 1e-30) {
      // Parallel to this pair of faces: inside the slab or nowhere.
      if (og[a] < 0.0 || og[a] > hi[a]) discard;
    } else {
      float ta = -og[a] / dg[a];
      float tb = (hi[a] - og[a]) / dg[a];
      t0 = max(t0, min(ta, tb));
      t1 = min(t1, max(ta, tb));
    }
  }
  if (!(t1 > t0)) discard;
  float offset = u_jitter != 0 ? pixel_jitter(gl_FragCoord.xy) : 0.5;
  vec3 color = vec3(0.0);
  float transmittance = 1.0;
  float knot[kVolumeKnots];
  int next_knot = knots && u_knots != 0 ? 0 : kVolumeKnots;
  float knot_t = next_knot < kVolumeKnots ? volume_knot(next_knot, knot_a, knot_b) : 1e30;
  for (int i = 0; i < kVolumeKnots; ++i) knot[i] = 1.0;
  int steps = int(ceil((t1 - t0) / u_step));
  int k = 0;
  while (k < steps) {
    float s0 = t0 + float(k) * u_step;
    float len = min(u_step, t1 - s0);
    vec3 g = og + (s0 + offset * len) * dg;
    int following = k + 1;
    if (u_skip_empty != 0) {
      // A brick whose values all have zero opacity: on to the first step
      // of the same grid that starts past the brick's far side (the
      // samples skipped would have added nothing).
      vec3 cell = clamp(floor(g / kBrickCells), vec3(0.0), vec3(textureSize(u_bricks, 0)) - 1.0);
      if (texelFetch(u_bricks, ivec3(cell), 0).r == 0u) {
        vec3 lo = cell * kBrickCells, hi = lo + kBrickCells;
        float exit_t = 1e30;
        for (int a = 0; a < 3; ++a) {
          if (abs(dg[a]) > 1e-30) exit_t = min(exit_t, ((dg[a] > 0.0 ? hi[a] : lo[a]) - og[a]) / dg[a]);
        }
        // The step containing the exit (its sample may still be inside).
        following = max(k + 1, int(floor((exit_t - t0) / u_step)));
        k = following;
        continue;
      }
    }
    k = following;
    float v = texture(u_values, (g + 0.5) / u_dims).r;
    vec4 tf = texture(u_transfer, (v * (kTransferTexels - 1.0) + 0.5) / kTransferTexels);
    // 1 - alpha = (1 - opacity)^e: the table holds log2(1 - opacity).
    float e = u_fixed_exponent >= 0.0 ? u_fixed_exponent : len / u_opacity_unit;
    float alpha = 1.0 - exp2(tf.a * e);
    // Knots within this step: the transmittance up to them, the step's
    // extinction taken as uniform over it.
    while (knot_t < s0 + len) {
      float part = clamp((knot_t - s0) / len, 0.0, 1.0);
      knot[next_knot] = transmittance * exp2(tf.a * e * part);
      ++next_knot;
      knot_t = next_knot < kVolumeKnots ? volume_knot(next_knot, knot_a, knot_b) : 1e30;
    }
    color += transmittance * alpha * tf.rgb;
    transmittance *= 1.0 - alpha;
    if (1.0 - transmittance >= u_ert) break;
  }
  // Knots beyond the volume (or past the early termination) see all of it.
  for (int i = next_knot; i < kVolumeKnots; ++i) knot[i] = transmittance;
  out_color = vec4(color, 1.0 - transmittance);
  out_knots0 = vec4(knot[0], knot[1], knot[2], knot[3]);
  out_knots1 = vec4(knot[4], knot[5], knot[6], knot[7]);
}
