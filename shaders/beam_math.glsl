// Density functions and their line integrals: the three integration methods
// (table, closed form, ray marching) behind one interface, g_diff/f_eval, that
// beam.frag's sphere, cylinder and cap pieces call. Derivations:
// docs/beam-math.md.

layout(binding = 0) uniform sampler2DArray u_g;     // g(d, s): x = column, y = row, layer = density
layout(binding = 1) uniform sampler1DArray u_f;     // f(x), layer = density
layout(binding = 3) uniform sampler1DArray u_warp;  // W(d) of warped layouts, layer = density
uniform ivec3 u_table_size;  // nd, ns, nf
uniform int u_warp_size;     // nw
uniform int u_method;        // 0 table, 1 closed form, 2 march
uniform int u_chord;         // table columns across the chord
uniform int u_warped;        // table rows placed by W(d)
uniform int u_shader_filter; // bilinear weights in the shader instead of the texture unit
uniform int u_samples;       // march: sub-intervals per piece
uniform int u_simpson;       // march: Simpson's rule instead of the midpoint rule
uniform int u_near_parallel; // 0: the paper's form at every angle (comparison only)
#ifdef BEAMCAST_MEDIUM
// A medium filling the scene (docs/media.md; program "beam_medium", which
// only scenes with a medium use): extinction per unit length, the rule of a
// beam's piece (0: Gauss on the density's moments, 1: midpoint) and the
// largest optical depth of one sub-piece.
uniform float u_sigma_t;
uniform int u_medium_rule;
uniform float u_medium_step;
layout(binding = 4) uniform sampler2DArray u_gm;  // (g, G1, G2, G3)
#endif

// The density of the beam being shaded (set once per fragment).
float g_layer;
int g_kind;      // protocol DensityKind: 0 abe, 1 shell, 2 linear, 3 quadratic, 4 gaussian, 5 table
float g_sigma;

float f_table(float x) {
  if (x >= 1.0) return 0.0;
  float n = float(u_table_size.z);
  return texture(u_f, vec2((x * (n - 1.0) + 0.5) / n, g_layer)).r;
}

// f(x) of the current density: exact for built-ins, the 1D table for user tables.
float f_eval(float x) {
  if (x >= 1.0 || x < 0.0) return 0.0;
  if (g_kind == 0) return x <= 0.01 ? 99.0 : 1.0 / x - 1.0;
  if (g_kind == 1) return (x > 0.75 && x < 0.85) ? 5.0 - abs(100.0 * (x - 0.8)) : 0.0;
  if (g_kind == 2) return 1.0 - x;
  if (g_kind == 3) return 1.0 - x * x;
  if (g_kind == 4) return exp(-x * x / (2.0 * g_sigma * g_sigma));
  return f_table(x);
}

// Linear interpolation of W(d) between its texels (full float weights: the row
// coordinate it feeds must be exact to well under a row).
float warp_eval(float d) {
  float x = d * float(u_warp_size - 1);
  int i = clamp(int(floor(x)), 0, u_warp_size - 2);
  float a = texelFetch(u_warp, ivec2(i, int(g_layer)), 0).r;
  float b = texelFetch(u_warp, ivec2(i + 1, int(g_layer)), 0).r;
  return mix(a, b, clamp(x - float(i), 0.0, 1.0));
}

// Table sample at continuous texel coordinates (column, row), texel centres at
// integers, clamped to the edge.
float table_sample(vec2 texel) {
  vec2 n = vec2(u_table_size.y, u_table_size.x);
  if (u_shader_filter == 0) return texture(u_g, vec3((texel + 0.5) / n, g_layer)).r;
  vec2 c = clamp(texel, vec2(0.0), n - 1.0);
  ivec2 i0 = ivec2(min(floor(c), n - 2.0));
  vec2 w = c - vec2(i0);
  int l = int(g_layer);
  float g00 = texelFetch(u_g, ivec3(i0, l), 0).r;
  float g10 = texelFetch(u_g, ivec3(i0 + ivec2(1, 0), l), 0).r;
  float g01 = texelFetch(u_g, ivec3(i0 + ivec2(0, 1), l), 0).r;
  float g11 = texelFetch(u_g, ivec3(i0 + ivec2(1, 1), l), 0).r;
  return mix(mix(g00, g10, w.x), mix(g01, g11, w.x), w.y);
}

// The table's row coordinate of d.
float table_row(float d) {
  return (u_warped != 0 ? warp_eval(d) : d) * float(u_table_size.x - 1);
}

// The table's column coordinate of s on a row whose chord half-length is c.
float table_column(float c, float s) {
  float cols = float(u_table_size.y - 1);
  if (u_chord != 0) return 0.5 * ((c > 0.0 ? clamp((s - 1.0) / c, -1.0, 1.0) : -1.0) + 1.0) * cols;
  return 0.5 * clamp(s, 0.0, 2.0) * cols;
}

// g(d, s1) - g(d, s0) from the table; the row (and its warp) and the chord are
// computed once for both ends, and an end before the chord needs no fetch
// (g = 0 there exactly).
float g_table_diff(float d, float s0, float s1) {
  float row = table_row(d);
  float c = sqrt(max((1.0 - d) * (1.0 + d), 0.0));
  float g1 = s1 <= 1.0 - c ? 0.0 : table_sample(vec2(table_column(c, s1), row));
  float g0 = s0 <= 1.0 - c ? 0.0 : table_sample(vec2(table_column(c, s0), row));
  return g1 - g0;
}

// Standard error function, Abramowitz & Stegun 7.1.26 (|error| <= 1.5e-7).
float erf_approx(float x) {
  float a = abs(x);
  float t = 1.0 / (1.0 + 0.3275911 * a);
  float poly = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 +
               t * (-1.453152027 + t * 1.061405429))));
  return sign(x) * (1.0 - poly * exp(-a * a));
}

// d^2 asinh(a / d) for a >= 0, finite at d = 0.
float d2_asinh(float d, float a, float u) { return d > 0.0 ? d * d * log((a + u) / d) : 0.0; }

// Antiderivative G(d, tau) = integral_0^tau f(sqrt(d^2 + t^2)) dt, odd in tau,
// for |tau| within the chord.
float antiderivative(float d, float tau) {
  float a = abs(tau);
  float u = sqrt(d * d + a * a);
  float v;
  if (g_kind == 0) {  // abe: 99 in the core x <= 0.01, else 1/x - 1
    const float xc = 0.01;
    if (d >= xc) {
      v = log((a + u) / d) - a;
    } else {
      float tc = sqrt((xc - d) * (xc + d));
      v = a <= tc ? 99.0 * a : 99.0 * tc + log((a + u) / (tc + xc)) - (a - tc);
    }
  } else if (g_kind == 2) {  // 1 - x
    v = a - 0.5 * (a * u + d2_asinh(d, a, u));
  } else if (g_kind == 3) {  // 1 - x^2
    v = a * (1.0 - d * d) - a * a * a / 3.0;
  } else {  // gaussian, cut at x = 1 (the chord clamp does the cut)
    const float kSqrtHalfPi = 1.2533141373155003;
    v = exp(-d * d / (2.0 * g_sigma * g_sigma)) * g_sigma * kSqrtHalfPi *
        erf_approx(a / (g_sigma * 1.4142135623730951));
  }
  return sign(tau) * v;
}

// g(d, s1) - g(d, s0) from the antiderivative, each end clamped to the chord.
float g_closed_diff(float d, float s0, float s1) {
  float c = sqrt(max((1.0 - d) * (1.0 + d), 0.0));
  return antiderivative(d, clamp(s1 - 1.0, -c, c)) - antiderivative(d, clamp(s0 - 1.0, -c, c));
}

// g(d, s1) - g(d, s0) by the selected method (the march method never asks).
float g_diff(float d, float s0, float s1) {
  return u_method == 1 ? g_closed_diff(d, s0, s1) : g_table_diff(d, s0, s1);
}

// ---- A beam seen through the medium (docs/media.md) ------------------------
#ifdef BEAMCAST_MEDIUM

// (g, G1, G2, G3) at s on the current density's row (row coordinate `row`,
// chord half-length c): the integral of f and of its first three moments
// about the chord's midpoint from the row's start to s; zero before the chord.
vec4 moments_at(float row, float c, float s) {
  if (s <= 1.0 - c) return vec4(0.0);
  vec2 texel = vec2(table_column(c, s), row);
  vec2 n = vec2(u_table_size.y, u_table_size.x);
  return texture(u_gm, vec3((texel + 0.5) / n, g_layer));
}

// Integral of f(...) e^(-sigma_t t(s)) ds over [s0, s1] of row d, with the
// ray distance t(s) = t0 + (s - s0) dt_ds (dt_ds > 0): a beam's piece
// attenuated from the eye and within itself. The part inside the chord is
// split into sub-pieces of optical depth at most u_medium_step (at most 32,
// over the first 32 of optical depth: beyond it the rest is attenuated by
// e^-32). Each sub-piece by the rule:
//   0: the two-node Gauss rule whose weight is f itself (its nodes and
//      weights from the sub-piece's moments m0..m3), e^(-sigma t) exact at
//      the nodes: exact when the attenuation is a cubic in s, error
//      ~ (sigma L)^4 (L the sub-piece's length);
//   1: m0 attenuated at the sub-piece's midpoint, error ~ (sigma L)^2.
// m0 is the method's own g difference (table or closed form); the moments
// only place the nodes.
float medium_piece(float d, float s0, float s1, float t0, float dt_ds) {
  float c = sqrt(max((1.0 - d) * (1.0 + d), 0.0));
  float a = max(s0, 1.0 - c);
  float b = min(s1, 1.0 + c);
  if (!(b > a)) return 0.0;
  float ta = t0 + (a - s0) * dt_ds;
  float k = u_sigma_t * dt_ds;  // optical depth per unit of s
  float len = min(b - a, 32.0 / k);
  int n = clamp(int(ceil(k * len / u_medium_step)), 1, 32);
  float h = len / float(n);
  float row = table_row(d);
  vec4 g_prev = moments_at(row, c, a);
  float sum = 0.0;
  for (int i = 0; i < n; ++i) {
    float sa = a + float(i) * h;
    float sb = i == n - 1 ? a + len : sa + h;
    vec4 g_next = moments_at(row, c, sb);
    vec4 m = g_next - g_prev;
    g_prev = g_next;
    float m0 = u_method == 1 ? g_closed_diff(d, sa, sb) : m.x;
    float mid = 0.5 * (sa + sb);
    if (u_medium_rule == 1 || !(m.x > 0.0)) {
      sum += m0 * exp(-u_sigma_t * ta - k * (mid - a));
      continue;
    }
    // Mean, variance and third central moment of f over the sub-piece in
    // tau = s - 1, kept to what a distribution on [lo, hi] can have
    // (interpolated table differences of a short sub-piece are noisy).
    float lo = sa - 1.0, hi = sb - 1.0;
    float mean = clamp(m.y / m.x, lo, hi);
    float e2 = m.z / m.x, e3 = m.w / m.x;
    float var = clamp(e2 - mean * mean, 0.0, (hi - mean) * (mean - lo));
    float k3 = e3 - 3.0 * mean * e2 + 2.0 * mean * mean * mean;
    float x1 = mean, x2 = mean, w1 = 0.5, w2 = 0.5;
    if (var > 1e-6 * (hi - lo) * (hi - lo)) {
      // Nodes mean + y, y^2 - (k3 / var) y - var = 0 (roots of opposite signs).
      float p = 0.5 * k3 / var;
      float q = sqrt(p * p + var);
      x1 = clamp(mean + p - q, lo, mean);
      x2 = clamp(mean + p + q, mean, hi);
      if (x2 > x1) {
        w1 = (x2 - mean) / (x2 - x1);
        w2 = 1.0 - w1;
      }
    }
    sum += m0 * (w1 * exp(-u_sigma_t * ta - k * (x1 + 1.0 - a)) +
                 w2 * exp(-u_sigma_t * ta - k * (x2 + 1.0 - a)));
  }
  return sum;
}

// g(d, s1) - g(d, s0) attenuated by the medium; t0 is the ray distance at
// s0 and dt_ds the ray length per unit of s.
float g_diff_seen(float d, float s0, float s1, float t0, float dt_ds) {
  return medium_piece(d, s0, s1, t0, dt_ds);
}

// e^(-sigma_t t): the attenuation from the eye to ray distance t.
float attenuation(float t) { return exp(-u_sigma_t * t); }
#else
// Without a medium (program "beam"): nothing is attenuated.
float g_diff_seen(float d, float s0, float s1, float t0, float dt_ds) { return g_diff(d, s0, s1); }
float attenuation(float t) { return 1.0; }
#endif

// One texel of s for the table; for the closed form the width under which its
// float cancellation (G(s1) - G(s0), divided by sin(theta)) is worse than the
// 3-point Gauss rule on a short interval.
// For the table, a wider band: there a short s-interval's table difference
// inherits the interpolation error of f across the table's rows (divided by an
// energy that shrinks with the interval), which the quadrature does not have.
float parallel_threshold() {
  return u_method == 1 ? 2e-3 : 0.25;
}
