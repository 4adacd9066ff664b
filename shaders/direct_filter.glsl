// Interleaved direct light brought together (pass "gi_resolve" with
// gi.direct_interleave 4; included by gi_resolve.frag after gi_surface.glsl,
// whose u_view_depth and u_gb_normal it reads): direct_split holds at each lit diffuse pixel the
// irradiance of the quarter of the interleaved points its place in the 2 x 2
// pattern chose, times 4. The 3 x 3 neighbours fall in four groups by their
// offset's parity, one per quarter: the pixel itself, its left and right,
// its top and bottom, its diagonals. Each group's mean over its neighbours
// on this pixel's surface (tent weights 1 2 1, which give each group the
// same total, 4 of 16) estimates its quarter's irradiance times 4, and the
// groups' means are averaged: every point counts, at a footprint of about
// 2 x 2 pixels. A neighbour counts if it was lit (w > 0: the direct pass
// writes the pixel's view depth there, which saves a depth fetch a
// neighbour) and lies within
// 0.1 of its distance of this pixel's tangent plane (an edge, a corner or a
// step in depth breaks the filter there); a group with no such neighbour is
// left out of the mean. (Until 2026-11-26 this was a pass of its own,
// "direct_filter"; here it shares the resolve's G-buffer reads.)
layout(binding = 4) uniform VIEW_SAMPLER u_split;

// This pixel, its surface point and normal, and the image's size.
vec3 g_x, g_n;
ivec2 g_px, g_size;

// The neighbour's tent weight if it counts, else 0 (and its irradiance in e).
float neighbour(int dx, int dy, float w, out vec3 e) {
  e = vec3(0.0);
  ivec2 q = g_px + ivec2(dx, dy);
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, g_size))) return 0.0;
  vec4 s = VIEW_TEXEL(u_split, q);
  if (s.w <= 0.0) return 0.0;
  vec3 d = view_point(vec2(q) + 0.5, s.w) - g_x;
  if (abs(dot(d, g_n)) > 0.1 * length(d)) return 0.0;
  e = w * s.rgb;
  return w;
}

// The filtered irradiance of the interleaved points at pixel px (surface
// point x, normal n); 0 where the direct pass lit no diffuse surface.
vec3 filtered_direct(ivec2 px, vec3 x, vec3 n) {
  vec4 own = VIEW_TEXEL(u_split, px);
  if (own.w <= 0.0) return vec3(0.0);  // not a lit diffuse pixel
  g_px = px;
  g_size = ivec2(cam.viewport.xy);
  g_x = x;
  g_n = n;
  vec3 e1, e2;
  // Left and right; top and bottom; the four diagonals.
  float wh = neighbour(-1, 0, 2.0, e1) + neighbour(1, 0, 2.0, e2);
  vec3 sh = e1 + e2;
  float wv = neighbour(0, -1, 2.0, e1) + neighbour(0, 1, 2.0, e2);
  vec3 sv = e1 + e2;
  float wd = neighbour(-1, -1, 1.0, e1) + neighbour(1, -1, 1.0, e2);
  vec3 sd = e1 + e2;
  wd += neighbour(-1, 1, 1.0, e1) + neighbour(1, 1, 1.0, e2);
  sd += e1 + e2;
  vec3 mean = own.rgb;
  float groups = 1.0;
  if (wh > 0.0) { mean += sh / wh; groups += 1.0; }
  if (wv > 0.0) { mean += sv / wv; groups += 1.0; }
  if (wd > 0.0) { mean += sd / wd; groups += 1.0; }
  return mean / groups;
}
