// The photon splats' sum to hdr (pass "gi_resolve"): brought from the
// splat size to the render size (each pixel from its 4 nearest splat pixels
// whose G-buffer points lie on its surface, bilinear weights), each splat
// pixel divided by its share (gi_share.frag: the kernel-weighted share of
// its disk that lies on its own surface, in the target's alpha; at least
// 0.25), times the pixel's albedo.
// The same pass antialiases the outlines of seen lights (light_outline.glsl;
// an outline is convex): the G-buffer shows a
// light where a pixel's centre sees it, with its full radiance, while the
// pixel's true value (the reference's, averaged over the pixel) is its
// radiance times the share of the pixel that sees it. Against the dim
// surfaces around a light that difference dominates a lit frame's error
// (56% of it on the Cornell box at 256x256, in 200 edge pixels). Each pixel
// gets sum_k c_k L_k minus the radiance its centre shows if that is a light,
// c_k being the share of 4x4 sub-pixel rays that meet light k's front no
// deeper than what the centre shows (1% deeper: the Cornell light hangs
// 0.1 under the ceiling). The sub-pixel rays are cast only where the rays
// through the pixel's corners do not all agree. What the rest of such a
// pixel shows is left out: the ceiling beside the light is ~3% of its
// radiance.
layout(binding = 3) uniform VIEW_SAMPLER u_indirect;  // rgb: the splats' sum; a: the share
uniform int u_correct;      // 0: no share correction (gi.edge_correction off)
uniform int u_direct_split;  // 1: the interleaved direct light to filter (direct_filter.glsl)
uniform int u_splat_scale;  // u_indirect has 1/u_splat_scale of the pixels per side
// u_indirect's bands (render/pass_plan.hpp, SplatBands): rows a band, texels
// from one band's start to the next's.
uniform ivec2 u_band_layout;

const int kMaxAaLights = 8;
uniform int u_aa_lights;        // seen lights to antialias (the first kMaxAaLights)
uniform int u_light_code[kMaxAaLights];     // LightOutline::code
uniform vec3 u_light_offset;    // the lights' anchor minus the eye
uniform vec3 u_light_corner[kMaxAaLights];  // the outline's parallelogram, relative to the anchor
uniform vec3 u_light_u[kMaxAaLights];
uniform vec3 u_light_v[kMaxAaLights];
uniform vec3 u_light_radiance[kMaxAaLights];
// The pixels (x0, y0, x1, y1, inclusive) where light k's outline can lie:
// its projection's bounds and 2 pixels, from the CPU; elsewhere the pixel
// neither sees nor touches the light, and its test is skipped (~2.5 ms of a
// 512^2 Cornell frame on llvmpipe).
uniform ivec4 u_light_rect[kMaxAaLights];

layout(location = 0) out vec4 out_color;

const float kPi = 3.14159265358979;

// A splat pixel's sum, divided by its share with the edge correction on.
vec3 corrected(ivec2 q) {
  vec4 v = VIEW_TEXEL(u_indirect, ivec2(q.x + (q.y / u_band_layout.x) * u_band_layout.y,
                                         q.y % u_band_layout.x));
  return u_correct != 0 ? v.rgb / max(v.a, 0.25) : v.rgb;
}

// The splat sum at render pixel px: its 4 nearest splat pixels, each kept
// if the G-buffer pixel it was splatted for (photon_splat.frag) is on px's
// surface, bilinear weights renormalized; the nearest if none is.
vec3 upsample(ivec2 px, vec3 x, vec3 n) {
  int s = u_splat_scale;
  if (s == 1) return corrected(px);
  ivec2 size = ivec2(cam.viewport.xy);
  ivec2 last = (size + s - 1) / s - 1;
  vec2 f = (vec2(px) + 0.5) / float(s) - 0.5;
  ivec2 q0 = ivec2(floor(f));
  vec2 a = f - vec2(q0);
  vec3 sum = vec3(0.0);
  float wsum = 0.0;
  for (int dy = 0; dy <= 1; ++dy) {
    for (int dx = 0; dx <= 1; ++dx) {
      ivec2 q = clamp(q0 + ivec2(dx, dy), ivec2(0), last);
      float w = (dx == 1 ? a.x : 1.0 - a.x) * (dy == 1 ? a.y : 1.0 - a.y);
      if (w <= 0.0 || !same_surface(min(q * s + s / 2, size - 1), x, n)) continue;
      sum += w * corrected(q);
      wsum += w;
    }
  }
  if (wsum > 0.0) return sum / wsum;
  return corrected(clamp(ivec2(floor(f + 0.5)), ivec2(0), last));
}

// Where the ray through pixel coordinate f meets light k's front, as
// (a, b) over its edges, and the view depth of the hit; w = 0 on a miss
// (parallel, behind the eye, or the light's back).
vec4 light_hit(vec2 f, int k) {
  ViewRay ray = view_ray(f);
  vec3 c = u_light_corner[k] + u_light_offset;
  vec3 n = cross(u_light_u[k], u_light_v[k]);
  float denom = dot(ray.dir, n);
  if (denom >= 0.0) return vec4(0.0);
  float t = dot(c - ray.origin, n) / denom;
  if (t <= 0.0) return vec4(0.0);
  vec3 p = ray.origin + t * ray.dir - c;
  float nn = dot(n, n);
  return vec4(dot(cross(p, u_light_v[k]), n) / nn, dot(cross(u_light_u[k], p), n) / nn,
              t * ray.cos_axis, 1.0);
}

bool inside(vec4 h, float zlim, int k) {
  return h.w > 0.0 && h.z <= zlim && outline_inside(u_light_code[k], h.xy);
}

// The area of the quadrilateral q (window positions, either winding) inside
// the square [lo, lo + 1]^2, by Green's theorem: the area of a region R
// inside the square is the integral around R's boundary of
// clamp(x - lo.x, 0, 1) dy over the y in [lo.y, lo.y + 1], summed edge by
// edge in closed form (no clipped polygon: llvmpipe pays for local arrays
// at every fragment of the pass, 16 ms at 512^2, measured 2026-11-27).
float clamp_integral(float u) {  // the integral of clamp(t, 0, 1) dt from 0 to u
  return u <= 0.0 ? 0.0 : (u < 1.0 ? 0.5 * u * u : u - 0.5);
}

float area_in_pixel(vec2 q[4], vec2 lo) {
  float area = 0.0;
  for (int i = 0; i < 4; ++i) {
    vec2 a = q[i] - lo, b = q[(i + 1) & 3] - lo;
    if (a.y == b.y) continue;
    float y0 = max(min(a.y, b.y), 0.0), y1 = min(max(a.y, b.y), 1.0);
    if (y1 <= y0) continue;
    float m = (b.x - a.x) / (b.y - a.y);  // dx / dy along the edge
    float u0 = a.x + (y0 - a.y) * m, u1 = a.x + (y1 - a.y) * m;
    float part = abs(u1 - u0) < 1e-4 ? clamp(0.5 * (u0 + u1), 0.0, 1.0) * (y1 - y0)
                                     : (clamp_integral(u1) - clamp_integral(u0)) / m;
    area += b.y > a.y ? part : -part;
  }
  return abs(area);
}

// The share of pixel px whose rays meet light k's front before depth zlim:
// 1 if the rays through its four corners all do, 0 if they all pass beyond
// the line of one of its edges, else the exact share of the pixel's square
// the light's outline covers (the reference's pixel average is a box
// filter), times the share of those of 4x4 sub-pixel rays that meet the
// light which meet it before zlim (something in front of it). Until
// 2026-11-27 the 4x4 rays' share alone: along a straight outline every
// pixel has the outline at the same place, so their 1/4-pixel steps did not
// average out (the Cornell light's top and bottom rows 15% too bright, 0.4%
// of the 512^2 image's error).
float light_coverage(ivec2 px, int k, float zlim) {
  // First the centre ray alone: farther from the light's outline than two
  // pixel footprints (at the hit, over the light's plane) decides it.
  vec4 hc = light_hit(vec2(px) + 0.5, k);
  if (hc.w == 0.0) return 0.0;
  vec3 n = cross(u_light_u[k], u_light_v[k]);
  float area = length(n);
  ViewRay ray = view_ray(vec2(px) + 0.5);
  // A pixel's size: in tangent units (perspective) or world units.
  float pixel = 2.0 * cam.cam_right.w / cam.viewport.y;
  float dist = is_orthographic() ? 1.0 : hc.z / ray.cos_axis;
  float foot = 2.0 * dist * pixel / max(abs(dot(ray.dir, n)) / area, 1e-3);
  // Distances to the edge lines: a in units of the height over edge v, b over edge u.
  vec2 h = vec2(area / length(u_light_v[k]), area / length(u_light_u[k]));
  float out_by = outline_outside(u_light_code[k], hc.xy, h);
  if (out_by > foot) return 0.0;
  if (out_by < -foot) return hc.z <= zlim ? 1.0 : 0.0;
  bool all_in = true;
  int misses = 0;
  // a < 0, a > 1, b < 0, b > 1 at every corner so far (beyond a line of the
  // parallelogram: outside any outline within it)
  bvec4 beyond = bvec4(true);
  for (int i = 0; i < 4; ++i) {
    vec4 h = light_hit(vec2(px) + vec2(i & 1, i >> 1), k);
    if (h.w == 0.0) {
      ++misses;
      all_in = false;
      continue;
    }
    all_in = all_in && inside(h, zlim, k);
    beyond = bvec4(beyond.x && h.x < 0.0, beyond.y && h.x > 1.0, beyond.z && h.y < 0.0,
                   beyond.w && h.y > 1.0);
  }
  if (all_in) return 1.0;
  if (misses == 4 || (misses == 0 && any(beyond))) return 0.0;
  float hits = 0.0, seen = 0.0;
  for (int j = 0; j < 16; ++j) {
    vec2 f = vec2(px) + (vec2(j & 3, j >> 2) + 0.5) / 4.0;
    vec4 h = light_hit(f, k);
    if (inside(h, 3.0e38, k)) {
      hits += 1.0;
      if (h.z <= zlim) seen += 1.0;
    }
  }
  // Other outlines than the whole parallelogram: the rays' share.
  if (u_light_code[k] != 1) return seen / 16.0;
  vec3 c = u_light_corner[k] + u_light_offset;
  vec2 q[4];
  if (!(window_of(c, q[0]) && window_of(c + u_light_u[k], q[1]) &&
        window_of(c + u_light_u[k] + u_light_v[k], q[2]) && window_of(c + u_light_v[k], q[3]))) {
    return seen / 16.0;  // a corner behind the eye: the rays' share
  }
  float covered = area_in_pixel(q, vec2(px));
  if (hits > 0.0) return covered * (seen / hits);
  return hc.z <= zlim ? covered : 0.0;
}

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  float z = VIEW_TEXEL(u_view_depth, px).r;
  vec4 albedo = VIEW_TEXEL(u_gb_albedo, px);
  // Light outlines first: every pixel may be one.
  vec3 lights = vec3(0.0);
  if (u_aa_lights > 0) {
    float zlim = z >= 1e29 ? 3.0e38 : 1.01 * z;
    for (int k = 0; k < u_aa_lights; ++k) {
      ivec4 r = u_light_rect[k];
      if (any(lessThan(px, r.xy)) || any(greaterThan(px, r.zw))) continue;
      lights += light_coverage(px, k, zlim) * u_light_radiance[k];
    }
    if (albedo.w > 2.5) lights -= albedo.rgb;  // the centre's light, drawn by the G-buffer
  }
  if (z >= 1e29 || albedo.w > 0.5) {  // no surface, or no photons there
    if (lights == vec3(0.0)) discard;
    out_color = vec4(lights, 0.0);
    return;
  }
  vec3 n = VIEW_TEXEL(u_gb_normal, px).xyz;
  vec3 x = surface_point(px, z);
  vec3 e = upsample(px, x, n);
  if (u_direct_split != 0) e += filtered_direct(px, x, n) * (1.0 / kPi);
  vec3 sum = albedo.rgb * e;
  out_color = vec4(sum + lights, 0.0);
}
