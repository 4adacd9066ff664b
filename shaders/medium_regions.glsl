// Regions of heterogeneous medium ("media", protocol/medium.hpp) for the
// passes that attenuate light: boxes and spheres with their own extinction,
// added to the scene-wide medium's u_sigma_t (set by each pass). Positions
// are world coordinates; u_region_eye is the view's eye (world), so a
// camera-relative point p is at p + u_region_eye. Compiled in only for the
// programs "<name>_regions" (the prelude medium_regions_on.glsl), which only
// scenes with regions use: on llvmpipe the loop below, even over no
// regions, made the volume pass 1.6x slower.
#ifdef BEAMCAST_MEDIUM_REGIONS
uniform int u_region_count;
uniform vec4 u_region_a[16];  // box: min (xyz), w 0; sphere: centre (xyz), w 1
uniform vec4 u_region_b[16];  // box: max (xyz); sphere: x radius; w: sigma_t
uniform vec3 u_region_eye;

// The regions' optical depth along o + t v (o camera-relative, |v| = 1),
// t in [t0, t1]: the sum of sigma_t times each region's chord.
float region_depth(vec3 o, vec3 v, float t0, float t1) {
  float tau = 0.0;
  vec3 ow = o + u_region_eye;
  for (int i = 0; i < u_region_count; ++i) {
    vec4 a = u_region_a[i];
    vec4 b = u_region_b[i];
    float lo = t0, hi = t1;
    if (a.w > 0.5) {
      vec3 oc = a.xyz - ow;
      float tc = dot(oc, v);
      vec3 perp = oc - tc * v;
      float h2 = b.x * b.x - dot(perp, perp);
      if (h2 <= 0.0) continue;
      float h = sqrt(h2);
      lo = max(lo, tc - h);
      hi = min(hi, tc + h);
    } else {
      vec3 inv = 1.0 / v;  // +-inf on an axis-parallel ray: the slab test still holds
      vec3 ta = (a.xyz - ow) * inv, tb = (b.xyz - ow) * inv;
      vec3 tmin = min(ta, tb), tmax = max(ta, tb);
      lo = max(lo, max(tmin.x, max(tmin.y, tmin.z)));
      hi = min(hi, min(tmax.x, min(tmax.y, tmax.z)));
    }
    if (hi > lo) tau += b.w * (hi - lo);
  }
  return tau;
}
#else
float region_depth(vec3 o, vec3 v, float t0, float t1) { return 0.0; }
#endif
