// Regions of heterogeneous medium ("media", protocol/medium.hpp) for the
// passes that attenuate light: boxes, spheres and closed triangle meshes
// with their own extinction,
// added to the scene-wide medium's u_sigma_t (set by each pass). Positions
// are world coordinates; u_region_eye is the view's eye (world), so a
// camera-relative point p is at p + u_region_eye. Compiled in only for the
// programs "<name>_regions" (the prelude medium_regions_on.glsl), which only
// scenes with regions use: on llvmpipe the loop below, even over no
// regions, made the volume pass 1.6x slower.
#ifdef BEAMCAST_MEDIUM_REGIONS
uniform int u_region_count;
// Each region's record (RegionGpu, protocol/media/region_base.hpp): a.w its
// kind's code, a.xyz and b.xyz two points, u_region_r a radius, b.w its
// sigma_t. Code 0 box: a min, b max; 1 sphere: a centre, r; 2 mesh: a, b
// its bounds, its triangles in MediumTriangles; 3 cylinder: a, b the ends
// of its axis, r.
uniform vec4 u_region_a[16];
uniform vec4 u_region_b[16];
uniform float u_region_r[16];
uniform ivec2 u_region_tris[16];  // mesh: its first triangle and their count
uniform vec3 u_region_eye;
// The mesh regions' triangles, world space, three vertices (xyz) each.
layout(std430, binding = 7) readonly buffer MediumTriangles { vec4 mesh_vertex[]; };

// v . (a x b) with no fused or reordered operation, so that swapping a and
// b negates it exactly (MediumRegion's triple() in protocol/medium.cpp).
float triple(vec3 v, vec3 a, vec3 b) {
  precise float cx = a.y * b.z - a.z * b.y;
  precise float cy = a.z * b.x - a.x * b.z;
  precise float cz = a.x * b.y - a.y * b.x;
  precise float r = v.x * cx + v.y * cy + v.z * cz;
  return r;
}

bool lex_less(vec3 a, vec3 b) {
  return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
}

// A line exactly through the edge (a, b) counts for one of the edge's two
// triangles when they face the same way, for both or neither when they do
// not (protocol/medium.cpp, edge_counts).
bool edge_counts(float e, bool back, vec3 a, vec3 b) {
  return (back ? e > 0.0 : e < 0.0) || (e == 0.0 && lex_less(a, b) != !back);
}

// The length of o + t v inside a mesh region, t in [lo, hi] (already
// clipped to its bounds): each crossing at t_c entering (+1) or leaving
// (-1) adds c (hi - clamp(t_c, lo, hi)).
float mesh_chord(vec3 ow, vec3 v, float lo, float hi, ivec2 tris) {
  float sum = 0.0;
  for (int k = tris.x; k < tris.x + tris.y; ++k) {
    vec3 w0 = mesh_vertex[3 * k].xyz, w1 = mesh_vertex[3 * k + 1].xyz,
         w2 = mesh_vertex[3 * k + 2].xyz;
    precise vec3 p0 = w0 - ow;
    precise vec3 p1 = w1 - ow;
    precise vec3 p2 = w2 - ow;
    float e0 = triple(v, p1, p2), e1 = triple(v, p2, p0), e2 = triple(v, p0, p1);
    float det = e0 + e1 + e2;
    if (det == 0.0) continue;
    bool back = det > 0.0;
    if (!edge_counts(e0, back, w1, w2) || !edge_counts(e1, back, w2, w0) ||
        !edge_counts(e2, back, w0, w1)) {
      continue;
    }
    vec3 n = cross(p1 - p0, p2 - p0);
    float t = dot(n, p0) / dot(n, v);
    sum += (back ? -1.0 : 1.0) * (hi - clamp(t, lo, hi));
  }
  return clamp(sum, 0.0, hi - lo);
}

// The regions' optical depth along o + t v (o camera-relative, |v| = 1),
// t in [t0, t1]: the sum of sigma_t times each region's chord.
float region_depth(vec3 o, vec3 v, float t0, float t1) {
  float tau = 0.0;
  vec3 ow = o + u_region_eye;
  for (int i = 0; i < u_region_count; ++i) {
    vec4 a = u_region_a[i];
    vec4 b = u_region_b[i];
    int kind = int(a.w + 0.5);
    float lo = t0, hi = t1;
    if (kind == 1) {  // a sphere
      vec3 oc = a.xyz - ow;
      float tc = dot(oc, v);
      vec3 perp = oc - tc * v;
      float r = u_region_r[i];
      float h2 = r * r - dot(perp, perp);
      if (h2 <= 0.0) continue;
      float h = sqrt(h2);
      lo = max(lo, tc - h);
      hi = min(hi, tc + h);
    } else if (kind == 3) {  // a cylinder: between its caps, within r of its axis
      vec3 axis = b.xyz - a.xyz;
      float len = length(axis);
      vec3 u = axis / len;
      vec3 w = ow - a.xyz;
      float wu = dot(w, u), vu = dot(v, u);
      if (vu != 0.0) {
        float ta = -wu / vu, tb = (len - wu) / vu;
        lo = max(lo, min(ta, tb));
        hi = min(hi, max(ta, tb));
      } else if (wu < 0.0 || wu > len) {
        continue;
      }
      vec3 wp = w - wu * u, vp = v - vu * u;
      float r = u_region_r[i];
      float a2 = dot(vp, vp);
      if (a2 > 0.0) {
        float tc = -dot(wp, vp) / a2;
        vec3 q = wp + tc * vp;
        float h2 = (r * r - dot(q, q)) / a2;
        if (h2 <= 0.0) continue;
        float h = sqrt(h2);
        lo = max(lo, tc - h);
        hi = min(hi, tc + h);
      } else if (dot(wp, wp) > r * r) {
        continue;
      }
    } else {  // a box, or a mesh's bounds
      vec3 inv = 1.0 / v;  // +-inf on an axis-parallel ray: the slab test still holds
      vec3 ta = (a.xyz - ow) * inv, tb = (b.xyz - ow) * inv;
      vec3 tmin = min(ta, tb), tmax = max(ta, tb);
      lo = max(lo, max(tmin.x, max(tmin.y, tmin.z)));
      hi = min(hi, min(tmax.x, min(tmax.y, tmax.z)));
    }
    if (hi <= lo) continue;
    tau += b.w * (kind == 2 ? mesh_chord(ow, v, lo, hi, u_region_tris[i]) : hi - lo);
  }
  return tau;
}
#else
float region_depth(vec3 o, vec3 v, float t0, float t1) { return 0.0; }
#endif
