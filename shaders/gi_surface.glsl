// The photon splats' surface tests and the share of a disk on its surface,
// shared by pass "photons"' share draw (gi_share.frag) and pass
// "gi_resolve" (gi_resolve.frag).
layout(binding = 0) uniform VIEW_SAMPLER u_view_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_gb_normal;
layout(binding = 2) uniform VIEW_SAMPLER u_gb_albedo;  // w: the material (surface.frag)
uniform float u_radius;
// The kernel, SplatKernel: 0 box, 1 cone, 2 Epanechnikov (set by the
// programs' preludes, gi_kernel_*.glsl).
#ifndef GI_KERNEL
#define GI_KERNEL 2
#endif
uniform float u_min_cos;    // the splats' normal test
uniform float u_max_plane;  // the splats' plane test, x radius

const float kTwoPi = 6.28318530717959;
const int kRings = 4;     // the disk's sample points: kRings rings
const int kPerRing = 12;  // of kPerRing points

vec3 surface_point(ivec2 px, float z) { return view_point(vec2(px) + 0.5, z); }

// The window position (pixel units) of camera-relative point p; false
// behind the eye (clip w <= 0), where it has none.
bool window_of(vec3 p, out vec2 f) {
  vec4 clip = cam.view_proj * vec4(p, 1.0);
  if (clip.w <= 0.0) return false;
  f = (clip.xy / clip.w * 0.5 + 0.5) * cam.viewport.xy;
  return true;
}

// The kernel's profile at distance fraction s = d / r (unnormalized).
float profile(float s) {
#if GI_KERNEL == 0
  return 1.0;
#elif GI_KERNEL == 1
  return 1.0 - s;
#else
  return 1.0 - s * s;
#endif
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

// The kernel-weighted share of the disk of radius r about x (normal n),
// in its tangent plane, that lies on x's surface, from 48 points of the
// disk projected into the G-buffer (the rules: gi_share.frag).
float disk_share(vec3 x, vec3 n) {
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
      vec2 f;
      if (!window_of(p, f)) {
        covered += w;
        continue;
      }
      ivec2 q = ivec2(floor(f));
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
        covered += w;
        continue;
      }
      // A quad light stops the photons that would reach what lies behind
      // it (the Cornell light hangs 0.1 under the ceiling): none there.
      if (VIEW_TEXEL(u_gb_albedo, q).w > 2.5) continue;
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
  return covered / total;
}
