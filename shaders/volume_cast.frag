// Scalar volume ray casting (pass "volumes", render/volume_pass.hpp; seed 004,
// docs/volumes.md). The pixel's centre ray is clipped to the volume's box
// (grid coordinates [0, n - 1]^3, protocol/volume.hpp) and to the nearest
// surface, then marched front to back in steps of u_step: one trilinear
// sample per step (at a per-pixel jittered fraction of it, or its middle),
// its transfer function's colour and opacity, the opacity corrected for the
// segment's length, alpha = 1 - (1 - opacity)^(length / opacity unit), or
// the seed's fixed exponent; or (VOLUME_PREINTEGRATED) each step between two
// samples looked up in the pre-integration table; stops once the opacity
// reaches u_ert. Written
// as (colour, opacity) and blended hdr = colour + (1 - opacity) hdr; the
// transmittance at the knots of volume_knots.glsl (multiplied into
// volume_t0/volume_t1 over the volumes) for the beams.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth
layout(binding = 1) uniform sampler3D u_values;         // normalized values, GL_R16
layout(binding = 2) uniform sampler1D u_transfer;       // (colour x intensity, log2(1 - opacity))
layout(binding = 3) uniform usampler3D u_bricks;        // 1: the brick can show something
layout(binding = 4) uniform sampler2D u_preint;         // (colour, log2 T) of a step from front to back value
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

layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_knots0;  // knots 0-3
layout(location = 2) out vec4 out_knots1;  // knots 4-7

const float kTransferTexels = 1024.0;  // render/volume_pass.hpp kTransferTexels
const float kBrickCells = 8.0;         // render/volume_pass.hpp kBrickCells
const float kPreintTexels = 256.0;     // render/volume_pass.hpp kPreintegrationTexels

// Where the ray leaves brick `cell` (grid coordinates og + t dg).
float brick_exit(vec3 cell, vec3 og, vec3 dg) {
  vec3 lo = cell * kBrickCells, hi = lo + kBrickCells;
  float exit_t = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (abs(dg[a]) > 1e-30) exit_t = min(exit_t, ((dg[a] > 0.0 ? hi[a] : lo[a]) - og[a]) / dg[a]);
  }
  return exit_t;
}

// Whether the brick of grid point g (its cell in the brick grid: `cell`) is
// empty, its values all of zero opacity.
bool brick_empty(vec3 g, out vec3 cell) {
  cell = clamp(floor(g / kBrickCells), vec3(0.0), vec3(textureSize(u_bricks, 0)) - 1.0);
  return texelFetch(u_bricks, ivec3(cell), 0).r == 0u;
}

float value_at(vec3 g) { return texture(u_values, (g + 0.5) / u_dims).r; }

// One pixel's march: its ray in grid coordinates, g(t) = m_og + t m_dg
// (t the world ray distance), clipped to [m_t0, m_t1]; its jitter; what it
// has gathered; the knots it has passed.
vec3 m_og, m_dg;
float m_t0, m_t1, m_offset;
vec3 m_color;
float m_transmittance;
float m_knot[kVolumeKnots];
int m_next_knot;
float m_knot_t, m_knot_a, m_knot_b;

// The knots before s + len, within a step [s, s + len] whose log2
// transmittance is log2_t: the transmittance up to each, the step's
// extinction taken as uniform over it.
void pass_knots(float s, float len, float log2_t) {
  while (m_knot_t < s + len) {
    float part = clamp((m_knot_t - s) / len, 0.0, 1.0);
    m_knot[m_next_knot] = m_transmittance * exp2(log2_t * part);
    ++m_next_knot;
    m_knot_t = m_next_knot < kVolumeKnots ? volume_knot(m_next_knot, m_knot_a, m_knot_b) : 1e30;
  }
}

// Each option of the march is compiled in or out by a prelude (VOLUME_SKIP,
// VOLUME_KNOTS, VOLUME_PREINTEGRATED; volume_*_on.glsl), one program each:
// on llvmpipe the knots' loop and the brick test, present but never taken,
// each cost about a quarter of a dense volume's march, and unused marches in
// the same shader more (docs/volumes.md, "Speed").

// One sample a step, at its jittered fraction. The sample's texture
// coordinate is ot + t dt and a full step's exponent is constant: only the
// last step (cut by the box or a surface) computes its own.
void march_points() {
  vec3 ot = (m_og + 0.5) / u_dims, dt = m_dg / u_dims;
  float e_full = u_fixed_exponent >= 0.0 ? u_fixed_exponent : u_step / u_opacity_unit;
  int steps = int(ceil((m_t1 - m_t0) / u_step));
  int k = 0;
  while (k < steps) {
    float s0 = m_t0 + float(k) * u_step;
    float len = u_step;
    float e = e_full;
    if (k == steps - 1) {
      len = m_t1 - s0;
      e = u_fixed_exponent >= 0.0 ? u_fixed_exponent : len / u_opacity_unit;
    }
    float t = s0 + m_offset * len;
#ifdef VOLUME_SKIP
    {
      // A brick whose values all have zero opacity: on to the first step
      // of the same grid that starts past the brick's far side (the
      // samples skipped would have added nothing).
      vec3 cell;
      if (brick_empty(m_og + t * m_dg, cell)) {
        float exit_t = brick_exit(cell, m_og, m_dg);
        // The step containing the exit (its sample may still be inside).
        k = max(k + 1, int(floor((exit_t - m_t0) / u_step)));
        continue;
      }
    }
#endif
    ++k;
    float v = texture(u_values, ot + t * dt).r;
    vec4 tf = texture(u_transfer, (v * (kTransferTexels - 1.0) + 0.5) / kTransferTexels);
    // 1 - alpha = (1 - opacity)^e: the table holds log2(1 - opacity).
    float alpha = 1.0 - exp2(tf.a * e);
#ifdef VOLUME_KNOTS
    pass_knots(s0, len, tf.a * e);
#endif
    m_color += m_transmittance * alpha * tf.rgb;
    m_transmittance *= 1.0 - alpha;
    if (1.0 - m_transmittance >= u_ert) break;
  }
}

// Pre-integrated steps between the nodes t0, t0 + (j + offset) u_step
// (j = 0, 1, ...) and t1: each looks up its front and back values in the
// table made for u_step; the first and last, shorter, scale its optical
// depth by their length (and its colour by their opacity's share).
void march_preintegrated() {
  float a = m_t0;
  float front = value_at(m_og + m_t0 * m_dg);
  int j = 0;  // the next node's index
  while (a < m_t1) {
#ifdef VOLUME_SKIP
    {
      // Front in an empty brick: on to the last node still inside it
      // (every value on the way, and between, has zero opacity).
      vec3 cell;
      if (brick_empty(m_og + a * m_dg, cell)) {
        float exit_t = brick_exit(cell, m_og, m_dg);
        if (exit_t >= m_t1) break;
        int last = int(floor((exit_t - m_t0) / u_step - m_offset));
        if (last >= j && m_t0 + (float(last) + m_offset) * u_step < exit_t) {
          j = last;
          a = m_t0 + (float(j) + m_offset) * u_step;
          front = value_at(m_og + a * m_dg);
          ++j;
        }
      }
    }
#endif
    float node = m_t0 + (float(j) + m_offset) * u_step;
    float b = min(node, m_t1);
    ++j;
    if (!(b > a)) continue;  // a zero offset: the first node is t0
    float back = value_at(m_og + b * m_dg);
    vec4 seg = texture(u_preint, (vec2(front, back) * (kPreintTexels - 1.0) + 0.5) / kPreintTexels);
    float log2_t = seg.a;
    vec3 c = seg.rgb;
    if (j == 1 || node > m_t1) {
      float share = (b - a) / u_step;
      float full = 1.0 - exp2(seg.a);
      log2_t = seg.a * share;
      c *= full > 1e-7 ? (1.0 - exp2(log2_t)) / full : share;
    }
#ifdef VOLUME_KNOTS
    pass_knots(a, b - a, log2_t);
#endif
    m_color += m_transmittance * c;
    m_transmittance *= exp2(log2_t);
    front = back;
    a = b;
    if (1.0 - m_transmittance >= u_ert) break;
  }
}

// Interleaved gradient noise: a per-pixel offset in [0, 1), the same every
// frame (frames stay reproducible, bit for bit, on any server).
float pixel_jitter(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main() {
  select_view(view_index());
  ViewRay ray = view_ray(gl_FragCoord.xy);
  m_t0 = ray.t_min;
  m_t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    m_t1 = min(m_t1, VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r / ray.cos_axis);
  }
  float t_end = m_t1;
  mat3 to_grid = transpose(u_rotation);
  m_og = (to_grid * (ray.origin - u_origin)) / u_spacing;
  m_dg = (to_grid * ray.dir) / u_spacing;
  vec3 hi = u_dims - 1.0;
  for (int a = 0; a < 3; ++a) {
    if (abs(m_dg[a]) < 1e-30) {
      // Parallel to this pair of faces: inside the slab or nowhere.
      if (m_og[a] < 0.0 || m_og[a] > hi[a]) discard;
    } else {
      float ta = -m_og[a] / m_dg[a];
      float tb = (hi[a] - m_og[a]) / m_dg[a];
      m_t0 = max(m_t0, min(ta, tb));
      m_t1 = min(m_t1, max(ta, tb));
    }
  }
  if (!(m_t1 > m_t0)) discard;
  m_offset = u_jitter != 0 ? pixel_jitter(gl_FragCoord.xy) : 0.5;
  m_color = vec3(0.0);
  m_transmittance = 1.0;
#ifdef VOLUME_KNOTS
  for (int i = 0; i < kVolumeKnots; ++i) m_knot[i] = 1.0;
  bool track = volume_knot_interval(ray, t_end, m_knot_a, m_knot_b);
  m_next_knot = track ? 0 : kVolumeKnots;
  m_knot_t = track ? volume_knot(0, m_knot_a, m_knot_b) : 1e30;
#endif
#ifdef VOLUME_PREINTEGRATED
  march_preintegrated();
#else
  march_points();
#endif
  out_color = vec4(m_color, 1.0 - m_transmittance);
#ifdef VOLUME_KNOTS
  // Knots beyond the volume (or past the early termination) see all of it.
  for (int i = m_next_knot; i < kVolumeKnots; ++i) m_knot[i] = m_transmittance;
  out_knots0 = vec4(m_knot[0], m_knot[1], m_knot[2], m_knot[3]);
  out_knots1 = vec4(m_knot[4], m_knot[5], m_knot[6], m_knot[7]);
#else
  out_knots0 = vec4(1.0);  // no attachment takes them (no beams)
  out_knots1 = vec4(1.0);
#endif
}
