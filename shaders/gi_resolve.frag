// The photon splats' sum to hdr (pass "gi_resolve"): brought from the
// splat size to the render size (each pixel from its 4 nearest splat pixels
// whose G-buffer points lie on its surface, bilinear weights), times the
// pixel's albedo, and divided by the kernel-weighted share of its disk
// (radius r, in its tangent plane)
// that lies on its own surface. Where the disk hangs over a surface's edge
// or into a corner, the photons of the missing part are missing from the
// sum; dividing by the share removes that bias for locally even light.
// The share is found in the G-buffer at 48 points of the disk (4 rings of
// 12), each projected into the image:
//   - the pixel shows the same surface (the splats' normal and plane tests):
//     covered;
//   - no surface, or the visible surface lies behind the point by more than
//     the plane tolerance (the point floats past an edge): not covered;
//   - the visible surface is in front of the point: not covered if its
//     plane separates the point from x (a concave corner: the wall's disk
//     reaches under the floor), else unknown, counted as covered (something
//     in front hides the rest of x's surface);
//   - off the image: unknown, covered.
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_gb_normal;
layout(binding = 2) uniform VIEW_SAMPLER u_gb_albedo;
layout(binding = 3) uniform VIEW_SAMPLER u_indirect;
uniform float u_radius;
uniform int u_kernel;       // SplatKernel: 0 box, 1 cone, 2 epanechnikov
uniform float u_min_cos;    // the splats' normal test
uniform float u_max_plane;  // the splats' plane test, x radius
uniform int u_correct;      // 0: no share correction (gi.edge_correction off)
uniform int u_splat_scale;  // u_indirect has 1/u_splat_scale of the pixels per side

layout(location = 0) out vec4 out_color;

const float kTwoPi = 6.28318530717959;
const int kRings = 4;     // the disk's sample points: kRings rings
const int kPerRing = 12;  // of kPerRing points

vec3 surface_point(ivec2 px, float z) {
  ViewRay ray = view_ray(vec2(px) + 0.5);
  return ray.origin + (z / ray.cos_axis) * ray.dir;
}

// The kernel's profile at distance fraction s = d / r (unnormalized).
float profile(float s) {
  if (u_kernel == 0) return 1.0;
  if (u_kernel == 1) return 1.0 - s;
  return 1.0 - s * s;
}

// True if the G-buffer pixel q lies on the surface of x (normal n): the
// splats' normal and plane tests.
bool same_surface(ivec2 q, vec3 x, vec3 n) {
  float zq = VIEW_TEXEL(u_view_depth, q).r;
  if (zq >= 1e29) return false;
  vec3 nq = VIEW_TEXEL(u_gb_normal, q).xyz;
  return dot(nq, n) >= u_min_cos &&
         abs(dot(surface_point(q, zq) - x, n)) <= u_max_plane * u_radius;
}

// The splat sum at render pixel px: its 4 nearest splat pixels, each kept
// if the G-buffer pixel it was splatted for (photon_splat.frag) is on px's
// surface, bilinear weights renormalized; the nearest if none is.
vec3 upsample(ivec2 px, vec3 x, vec3 n) {
  int s = u_splat_scale;
  if (s == 1) return VIEW_TEXEL(u_indirect, px).rgb;
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
      sum += w * VIEW_TEXEL(u_indirect, q).rgb;
      wsum += w;
    }
  }
  if (wsum > 0.0) return sum / wsum;
  return VIEW_TEXEL(u_indirect, clamp(ivec2(floor(f + 0.5)), ivec2(0), last)).rgb;
}

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  float z = VIEW_TEXEL(u_view_depth, px).r;
  vec4 albedo = VIEW_TEXEL(u_gb_albedo, px);
  if (z >= 1e29 || albedo.w > 0.5) discard;  // no surface, or no photons there
  vec3 n = VIEW_TEXEL(u_gb_normal, px).xyz;
  vec3 x = surface_point(px, z);
  vec3 sum = albedo.rgb * upsample(px, x, n);
  out_color = vec4(sum, 0.0);
  if (u_correct == 0 || sum == vec3(0.0)) return;
  vec3 t = normalize(cross(n, abs(n.x) < 0.7 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
  vec3 b = cross(n, t);
  ivec2 size = ivec2(cam.viewport.xy);
  float covered = 0.0, total = 0.0;
  for (int ring = 0; ring < kRings; ++ring) {
    float s = (float(ring) + 0.5) / float(kRings);
    // Each ring stands for an annulus of area ~ s: weight profile x s.
    float w = profile(s) * s;
    for (int k = 0; k < kPerRing; ++k) {
      float phi = (float(k) + 0.5 * float(ring)) * (kTwoPi / float(kPerRing));
      vec3 p = x + (u_radius * s) * (cos(phi) * t + sin(phi) * b);
      total += w;
      vec4 clip = cam.view_proj * vec4(p, 1.0);
      if (clip.w <= 0.0) {
        covered += w;
        continue;
      }
      ivec2 q = ivec2(floor((clip.xy / clip.w * 0.5 + 0.5) * cam.viewport.xy));
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
        covered += w;
        continue;
      }
      if (same_surface(q, x, n)) {
        covered += w;
        continue;
      }
      float zq = VIEW_TEXEL(u_view_depth, q).r;
      if (zq >= 1e29) continue;
      float zp = dot(p, cam.cam_forward.xyz);  // view depth of p
      if (zq > zp + u_max_plane * u_radius) continue;  // past an edge: empty space
      vec3 xq = surface_point(q, zq);
      vec3 nq = VIEW_TEXEL(u_gb_normal, q).xyz;
      bool separated = dot(p - xq, nq) < 0.0 && dot(x - xq, nq) > 0.0;
      if (!separated) covered += w;
    }
  }
  out_color = vec4(sum / max(covered / total, 0.25), 0.0);
}
