// The outlines of the lights a camera sees (LightOutline,
// protocol/lights/light_base.hpp): a flat one-sided emitter whose emitting
// part lies inside the parallelogram corner + a u + b v, a and b in [0, 1],
// and is picked by the kind's code (its kOutlineCode):
//   1 (quad): all of it;
//   2 (disk): the disk inscribed in the square u, v (|u| = |v|, u . v = 0).
// A kind with another shape adds its code's branch to both functions.

// Whether the point at (a, b) over the parallelogram emits.
bool outline_inside(int code, vec2 ab) {
  if (code == 1) {
    return all(greaterThanEqual(ab, vec2(0.0))) && all(lessThanEqual(ab, vec2(1.0)));
  }
  if (code == 2) return dot(2.0 * ab - 1.0, 2.0 * ab - 1.0) <= 1.0;
  return false;
}

// How far the point at (a, b) lies outside the emitting part, in world
// units (< 0 inside), where h is the parallelogram's height over edge v and
// over edge u (a in units of h.x, b of h.y).
float outline_outside(int code, vec2 ab, vec2 h) {
  if (code == 1) {
    vec2 out_by = max(-ab, ab - 1.0) * h;  // > 0 outside, per pair of edges
    return max(out_by.x, out_by.y);
  }
  if (code == 2) return (length(2.0 * ab - 1.0) - 1.0) * 0.5 * h.x;  // h.x = |u| = 2 radius
  return 3.0e38;
}
