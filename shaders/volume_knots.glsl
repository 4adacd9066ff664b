// The volumes' transmittance knots (render/pass_plan.cpp, targets volume_t0
// and volume_t1): the pass "volumes" writes them, the beams read them, both
// through these functions, so both place the knots at the same float values.
// A pixel's ray is clipped to the box around every volume (u_volume_lo/hi,
// relative to the eye) and to [t_min, t_end]; that interval [a, b] is cut
// into 7 equal segments. Knot k < 7 holds the volumes' transmittance from the
// eye to segment k's middle, knot 7 the transmittance to b; a beam's light in
// segment k is weighted by knot k (the transmittance's variation within a
// segment is the method's error, docs/volumes.md), beyond b by knot 7.
uniform vec3 u_volume_lo;
uniform vec3 u_volume_hi;

const int kVolumeKnots = 8;
const float kVolumeSegments = 7.0;

bool volume_knot_interval(ViewRay ray, float t_end, out float a, out float b) {
  a = ray.t_min;
  b = t_end;
  for (int k = 0; k < 3; ++k) {
    float d = ray.dir[k];
    float o = ray.origin[k];
    if (abs(d) < 1e-30) {
      if (o < u_volume_lo[k] || o > u_volume_hi[k]) return false;
      continue;
    }
    float ta = (u_volume_lo[k] - o) / d;
    float tb = (u_volume_hi[k] - o) / d;
    a = max(a, min(ta, tb));
    b = min(b, max(ta, tb));
  }
  return b > a;
}

// Where knot k lies in [a, b].
float volume_knot(int k, float a, float b) {
  return k == kVolumeKnots - 1 ? b : a + (float(k) + 0.5) * (b - a) / kVolumeSegments;
}
