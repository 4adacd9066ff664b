// Interleaved direct light brought together (pass "direct_filter",
// gi.direct_interleave 4): direct_split holds at each lit diffuse pixel the
// irradiance of the quarter of the interleaved points its place in the 2 x 2
// pattern chose, times 4. The 3 x 3 neighbours fall in four groups by their
// offset's parity, one per quarter: the pixel itself, its left and right,
// its top and bottom, its diagonals. Each group's mean over its neighbours
// on this pixel's surface (tent weights 1 2 1, which give each group the
// same total, 4 of 16) estimates its quarter's irradiance times 4, and the
// groups' means are averaged: every point counts, at a footprint of about
// 2 x 2 pixels. A neighbour counts if it was lit (w = 1) and lies within
// 0.1 of its distance of this pixel's tangent plane (an edge, a corner or a
// step in depth breaks the filter there); a group with no such neighbour is
// left out of the mean. Adds albedo / pi x the irradiance to hdr.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_gb_normal;
layout(binding = 2) uniform VIEW_SAMPLER u_gb_albedo;
layout(binding = 3) uniform VIEW_SAMPLER u_split;

layout(location = 0) out vec4 out_color;

const float kPi = 3.14159265358979;

// This pixel, its surface point and normal, and the image's size.
vec3 g_x, g_n;
ivec2 g_px, g_size;

// The neighbour's tent weight if it counts, else 0 (and its irradiance in e).
float neighbour(int dx, int dy, float w, out vec3 e) {
  e = vec3(0.0);
  ivec2 q = g_px + ivec2(dx, dy);
  if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, g_size))) return 0.0;
  vec4 s = VIEW_TEXEL(u_split, q);
  if (s.w < 0.5) return 0.0;
  float zq = VIEW_TEXEL(u_view_depth, q).r;
  vec3 d = view_point(vec2(q) + 0.5, zq) - g_x;
  if (abs(dot(d, g_n)) > 0.1 * length(d)) return 0.0;
  e = w * s.rgb;
  return w;
}

void main() {
  select_view(view_index());
  g_px = ivec2(gl_FragCoord.xy);
  vec4 own = VIEW_TEXEL(u_split, g_px);
  if (own.w < 0.5) discard;  // not a lit diffuse pixel
  g_size = ivec2(cam.viewport.xy);
  g_x = view_point(gl_FragCoord.xy, VIEW_TEXEL(u_view_depth, g_px).r);
  g_n = VIEW_TEXEL(u_gb_normal, g_px).xyz;
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
  vec4 albedo = VIEW_TEXEL(u_gb_albedo, g_px);
  out_color = vec4(albedo.rgb / kPi * (mean / groups), 0.0);
}
