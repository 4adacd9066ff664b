// Energy of one beam along the view ray.
//
// Units: energy = (1/r) * integral of f(dist / r) dt, path length in radii.
// A capsule is a cylinder clipped to its slab plus optional hemispherical caps;
// a sphere beam is one sphere piece. Every method shares this decomposition and
// the clipping of the ray to [near plane, nearest surface]; they differ only in
// how a piece's integral is evaluated (beam_math.glsl, g_diff):
// Sphere (centre A): t_c = (A - o).v, d = |(A - o) x v|, s(t) = (t - t_c)/r + 1,
//   E = g(d/r, s(t1)) - g(d/r, s(t0)).
// Cylinder (point A, unit axis w): c = w x v, sin(theta) = |c|, c^ = c/|c|,
//   d = |(o - A).c^|, s(t) = (sin(theta) t + ((w x (o - A)).c^)) / r + 1,
//   E = [g(d/r, s(t1)) - g(d/r, s(t0))] / sin(theta)
// (docs/beam-math.md derives both; the paper's eq 2.8/2.9 are wrong).
// Where the s-interval is short (rays near-parallel to the axis) the difference
// divided by sin(theta) amplifies interpolation error, so a composite Gauss
// rule on f takes over, blended smoothly (docs/stability.md).

struct BeamData {
  vec4 p0_radius;
  vec4 axis_length;
  vec4 color_layer;
  vec4 caps_kind;
  vec4 density;  // x: DensityKind, y: gaussian sigma
};
layout(std430, binding = 1) readonly buffer Beams { BeamData beams[]; };

layout(binding = 2) uniform VIEW_SAMPLER u_view_depth;  // surfaces' view depth (huge: none)
uniform int u_has_surfaces;
#ifdef BEAMCAST_VOLUMES
// Scenes with volumes: their transmittance knots (volume_knots.glsl).
layout(binding = 5) uniform VIEW_SAMPLER u_volume_t0;
layout(binding = 6) uniform VIEW_SAMPLER u_volume_t1;
#endif

flat in int v_beam;
layout(location = 0) out vec4 out_energy;

// Distance of o + t v from the centre (point piece) or the axis (line piece),
// with m = o - A.
float piece_distance(bool line, vec3 m, vec3 v, vec3 w, float t) {
  vec3 p = m + t * v;
  return line ? length(cross(p, w)) : length(p);
}

// (1/r) * integral of f over [ta, tb] with u_samples sub-intervals.
float march(bool line, vec3 m, vec3 v, vec3 w, float r, float ta, float tb) {
  if (!(tb > ta)) return 0.0;
  int n = u_samples;
  float h = (tb - ta) / float(n);
  float sum = 0.0;
  if (u_simpson == 0) {
    for (int k = 0; k < n; ++k) {
      float t = ta + (float(k) + 0.5) * h;
      sum += f_eval(piece_distance(line, m, v, w, t) / r) * attenuation(t);
    }
    return sum * h / r;
  }
  for (int k = 0; k <= n; ++k) {
    float wk = (k == 0 || k == n) ? 1.0 : ((k & 1) == 1 ? 4.0 : 2.0);
    float t = ta + float(k) * h;
    sum += wk * f_eval(piece_distance(line, m, v, w, t) / r) * attenuation(t);
  }
  return sum * h / (3.0 * r);
}

float sphere_energy(vec3 o, vec3 v, vec3 center, float r, float t0, float t1) {
  if (!(t1 > t0)) return 0.0;
  vec3 to_c = center - o;
  float tc = dot(to_c, v);
  float d = length(cross(to_c, v)) / r;
  if (d >= 1.0) return 0.0;
  if (u_method == 2) {  // march over the chord only
    float h = r * sqrt((1.0 - d) * (1.0 + d));
    return march(false, -to_c, v, vec3(0.0), r, max(t0, tc - h), min(t1, tc + h));
  }
  return g_diff_seen(d, (t0 - tc) / r + 1.0, (t1 - tc) / r + 1.0, t0, r);
}

float cylinder_energy(vec3 o, vec3 v, vec3 a, vec3 w, float r, float t0, float t1) {
  if (!(t1 > t0)) return 0.0;
  vec3 m = o - a;
  vec3 c = cross(w, v);
  float sin_t = length(c);
  if (u_method == 2) {
    float ta = t0, tb = t1;
    if (sin_t > 1e-12) {
      vec3 ch = c / sin_t;
      float d = abs(dot(m, ch)) / r;
      if (d >= 1.0) return 0.0;
      float tc = -dot(cross(w, m), ch) / sin_t;
      float half_len = r * sqrt((1.0 - d) * (1.0 + d)) / sin_t;
      ta = max(t0, tc - half_len);
      tb = min(t1, tc + half_len);
    } else if (length(cross(m, w)) >= r) {
      return 0.0;
    }
    return march(true, m, v, w, r, ta, tb);
  }
  float dt = t1 - t0;
  float ds = sin_t * dt / r;
  float threshold = parallel_threshold();
  // u_near_parallel == 0: the paper's form at every angle; it divides by
  // sin(theta) = 0 for an exactly parallel ray, which contributes nothing.
  float alpha = u_near_parallel == 0 ? (sin_t > 0.0 ? 1.0 : 0.0)
                                     : smoothstep(0.5 * threshold, threshold, ds);
  if (u_near_parallel == 0 && alpha == 0.0) return 0.0;
  float e = 0.0;
  if (alpha > 0.0) {
    vec3 ch = c / sin_t;
    float d = abs(dot(m, ch)) / r;
    if (d < 1.0) {
      float q = dot(cross(w, m), ch);
      float s0 = (sin_t * t0 + q) / r + 1.0;
      float s1 = (sin_t * t1 + q) / r + 1.0;
      e += alpha * g_diff_seen(d, s0, s1, t0, r / sin_t) / sin_t;
    }
  }
  if (alpha < 1.0) {
    // Only the part of [t0, t1] inside the cylinder (rho < 1): a density cut
    // at x = 1 (gaussian, user tables) jumps to 0 there, which a Gauss panel
    // straddling the crossing would smear over the whole panel. The chord from
    // d is trustworthy once sin(theta) >= 1e-4 (c = w x v known to ~1e-3
    // relative); below that rho changes by under 1e-4 per radius of path.
    float ga = t0, gb = t1;
    if (sin_t >= 1e-4) {
      vec3 ch = c / sin_t;
      float d = abs(dot(m, ch)) / r;
      float tc = -dot(cross(w, m), ch) / sin_t;
      float half_len = r * sqrt(max((1.0 - d) * (1.0 + d), 0.0)) / sin_t;
      ga = max(t0, tc - half_len);
      gb = min(t1, tc + half_len);
    }
    if (gb > ga) {
      // Composite Gauss-Legendre, 3 nodes per panel, panels no wider than
      // 0.02 in s (a fraction of the thin shell's width), at most 16; rho
      // measured directly to the axis, f exact for built-in densities.
      const float xk[3] = float[3](-0.7745966692414834, 0.0, 0.7745966692414834);
      const float wk[3] = float[3](0.5555555555555556, 0.8888888888888888, 0.5555555555555556);
      int panels = clamp(int(ceil(sin_t * (gb - ga) / r / 0.02)), 1, 16);
      float h = (gb - ga) / float(panels);
      float sum = 0.0;
      for (int p = 0; p < panels; ++p) {
        for (int k = 0; k < 3; ++k) {
          float t = ga + h * (float(p) + 0.5 * (1.0 + xk[k]));
          sum += wk[k] * f_eval(piece_distance(true, m, v, w, t) / r) * attenuation(t);
        }
      }
      e += (1.0 - alpha) * 0.5 * h / r * sum;
    }
  }
  return e;
}

// Restricts [t0, t1] to the part of the ray where u(t) = u0 + t du is >= bound
// (above = true) or <= bound (above = false).
void clip_plane(float u0, float du, float bound, bool above, inout float t0, inout float t1) {
  if (du == 0.0) {
    bool inside = above ? (u0 >= bound) : (u0 <= bound);
    if (!inside) t1 = t0;
    return;
  }
  float t = (bound - u0) / du;
  bool entering = above == (du > 0.0);  // crossing the plane into the allowed side
  if (entering) {
    t0 = max(t0, t);
  } else {
    t1 = min(t1, t);
  }
}

// The beam's energy along the ray for t in [t0, t1].
float beam_energy(BeamData b, ViewRay ray, float t0, float t1) {
  if (!(t1 > t0)) return 0.0;
  float r = b.p0_radius.w;
  vec3 p0 = b.p0_radius.xyz;
  float e;
  if (b.caps_kind.z < 0.5) {
    e = sphere_energy(ray.origin, ray.dir, p0, r, t0, t1);
  } else {
    vec3 w = b.axis_length.xyz;
    float len = b.axis_length.w;
    float u0 = dot(ray.origin - p0, w);
    float du = dot(ray.dir, w);
    // Cylinder: 0 <= u <= len.
    float ca = t0, cb = t1;
    clip_plane(u0, du, 0.0, true, ca, cb);
    clip_plane(u0, du, len, false, ca, cb);
    e = cylinder_energy(ray.origin, ray.dir, p0, w, r, ca, cb);
    if (b.caps_kind.x > 0.5) {  // hemisphere beyond p0: u <= 0
      float sa = t0, sb = t1;
      clip_plane(u0, du, 0.0, false, sa, sb);
      e += sphere_energy(ray.origin, ray.dir, p0, r, sa, sb);
    }
    if (b.caps_kind.y > 0.5) {  // hemisphere beyond p1: u >= len
      float sa = t0, sb = t1;
      clip_plane(u0, du, len, true, sa, sb);
      e += sphere_energy(ray.origin, ray.dir, p0 + len * w, r, sa, sb);
    }
  }
  return e;
}

void main() {
  select_view(view_index());
  BeamData b = beams[v_beam];
  g_layer = b.color_layer.w;
  g_kind = int(b.density.x);
  g_sigma = b.density.y;
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    float z = VIEW_TEXEL(u_view_depth, ivec2(gl_FragCoord.xy)).r;
    t1 = min(t1, z / ray.cos_axis);
  }
#ifdef BEAMCAST_VOLUMES
  // Behind and inside volumes: the light of each knot segment weighted by
  // the transmittance at its middle, beyond them by the whole volumes'
  // (piece 0: before the volumes, 1-7: the segments, 8: beyond). One call
  // site, so the energy's code is compiled once.
  float a = 0.0, c = 0.0;
  bool inside = volume_knot_interval(ray, t1, a, c);
  vec4 k0 = VIEW_TEXEL(u_volume_t0, ivec2(gl_FragCoord.xy));
  vec4 k1 = VIEW_TEXEL(u_volume_t1, ivec2(gl_FragCoord.xy));
  float h = (c - a) / kVolumeSegments;
  int pieces = inside ? kVolumeKnots + 1 : 1;
  float e = 0.0;
  for (int k = 0; k < pieces; ++k) {
    float sa = t0, sb = t1, weight = 1.0;
    if (inside) {
      sa = k == 0 ? t0 : k == kVolumeKnots ? c : a + float(k - 1) * h;
      sb = k == 0 ? a : k >= kVolumeKnots - 1 ? (k == kVolumeKnots ? t1 : c) : a + float(k) * h;
      weight = k == 0 ? 1.0 : k <= 4 ? k0[k - 1] : k1[k - 5];
    }
    e += weight * beam_energy(b, ray, sa, sb);
  }
#else
  float e = beam_energy(b, ray, t0, t1);
#endif
#ifdef BEAMCAST_MEDIUM_REGIONS
  // Regions of medium (medium_regions.glsl): their optical depth to the
  // ray's point nearest the beam's centre (the scene-wide medium is exact,
  // in medium_piece; the regions' variation across the beam is not).
  vec3 p0 = b.p0_radius.xyz;
  vec3 centre = b.caps_kind.z < 0.5 ? p0 : p0 + 0.5 * b.axis_length.w * b.axis_length.xyz;
  float tm = clamp(dot(centre - ray.origin, ray.dir), t0, t1);
  e *= exp(-region_depth(ray.origin, ray.dir, 0.0, tm));
#endif
  out_energy = vec4(b.color_layer.rgb * max(e, 0.0), 0.0);
}
