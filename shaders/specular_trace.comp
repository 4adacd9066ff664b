// Mirror and glass pixels on the GPU (pass "specular", render/specular_gpu.hpp):
// for each G-buffer pixel of material 1 (mirror) or 2 (glass), K x K rays
// over the pixel followed through mirrors and glass to what they reach, as
// LitShading does on the CPU (gi/photon_gather.hpp): a diffuse surface
// shows the fixed-radius photon estimate (both maps, each with its radius
// and the splat tests) plus, with gi.direct "shadow_maps", the direct
// points' light with shadow rays; a seen light (quad, ...) from its front its
// radiance; nothing, the background. A mirror multiplies by its
// reflectance, glass adds F x the reflected and (1 - F) x tint x the
// refracted branch (exact unpolarized Fresnel), every branch followed (a
// stack, not recursion) up to 8 specular bounces or a branch weight of
// 1e-3. The mean goes to the "specular" target, which specular_add adds to
// hdr. Positions are relative to the scene's anchor (SpecularGpu::anchor).
// Groups of 8 x 8; of one invocation in "specular_trace_serial", the
// software rasterizer's program (specular_serial_on.glsl says why).
#ifdef SPECULAR_SERIAL
layout(local_size_x = 1, local_size_y = 1) in;
#else
layout(local_size_x = 8, local_size_y = 8) in;
#endif

// a.w: 0 plane (a.xyz a point, b.xyz the unit normal), 1 sphere (a.xyz the
// centre, b.w the radius), 2 seen light (LightOutline: a.xyz the corner, b.xyz
// and c.xyz the edges u and v, d.xyz cross(u, v), d.w the outline code,
// light_outline.glsl); c.w: the material.
struct Shape {
  vec4 a;
  vec4 b;
  vec4 c;
  vec4 d;
};
layout(std430, binding = 1) readonly buffer SpecShapes { Shape shapes[]; };
// albedo.w: 0 diffuse, 1 mirror, 2 glass, 3 light (albedo.rgb its radiance);
// specular.rgb: the mirror's reflectance or the glass's tint, specular.w its ior.
struct SpecMaterial {
  vec4 albedo;
  vec4 specular;
};
layout(std430, binding = 2) readonly buffer SpecMaterials { SpecMaterial materials[]; };
// count 0: an inner node, children at first and first + 1; else a leaf of
// triangles [first, first + count).
struct BvhNode {
  vec3 lo;
  int first;
  vec3 hi;
  int count;
};
layout(std430, binding = 3) readonly buffer SpecBvh { BvhNode nodes[]; };
// a.w: the material; e1.w: 1 one-sided (hit only from the side n points to).
struct SpecTriangle {
  vec4 a;
  vec4 e1;
  vec4 e2;
  vec4 n;
};
layout(std430, binding = 4) readonly buffer SpecTriangles { SpecTriangle tris[]; };
// w components: the photon's grid cell.
struct SpecPhoton {
  vec4 p;
  vec4 n;
  vec4 power;
};
layout(std430, binding = 5) readonly buffer SpecPhotons { SpecPhoton photons[]; };
// Grid g's bucket h holds photons [cells[base + h], cells[base + h + 1]).
layout(std430, binding = 6) readonly buffer SpecCells { uint cells[]; };
// p.w: mode (0 isotropic, 1 cosine, 2 cone); axis.w: scale; flux.w: cos_inner; cone.x: cos_outer.
struct SpecDirect {
  vec4 p;
  vec4 axis;
  vec4 flux;
  vec4 cone;
};
layout(std430, binding = 7) readonly buffer SpecDirects { SpecDirect direct[]; };

layout(binding = 0) uniform VIEW_SAMPLER u_albedo;  // gb_albedo (w: material)
#ifdef BEAMCAST_MULTIVIEW
layout(rgba32f, binding = 0) writeonly uniform image2DArray u_out;
void store(ivec2 p, vec4 v) { imageStore(u_out, ivec3(p, u_view), v); }
#else
layout(rgba32f, binding = 0) writeonly uniform image2D u_out;
void store(ivec2 p, vec4 v) { imageStore(u_out, p, v); }
#endif

uniform vec3 u_eye;  // this view's eye minus the anchor
uniform int u_samples;
uniform int u_shape_count;
uniform int u_node_count;
uniform int u_direct_count;
uniform float u_eps;
uniform vec3 u_background;
uniform int u_kernel;  // 0 box, 1 cone, 2 Epanechnikov
uniform vec3 u_grid_origin[2];
uniform float u_grid_inv_cell[2];
uniform float u_grid_radius[2];
uniform int u_grid_base[2];
uniform int u_grid_mask[2];  // -1: no photons

const float kPi = 3.14159265358979;
const int kMaxDepth = 8;       // LitShading::kMaxSpecularDepth
const float kMinWeight = 1e-3;
const float kMinCos = 0.906;   // SplatTests
const float kMaxPlane = 0.1;
const float kFar = 3.0e38;     // a ray beyond a mirror or through glass: no end

struct Hit {
  float t;
  vec3 n;  // unit, not yet turned toward the ray
  int material;
};

// The nearest hit in (t_min, t_max]; material -1: none.
Hit nearest(vec3 o, vec3 v, float t_min, float t_max) {
  Hit h;
  h.t = t_max;
  h.material = -1;
  for (int i = 0; i < u_shape_count; ++i) {
    Shape s = shapes[i];
    int kind = int(s.a.w);
    if (kind == 1) {  // SphereOccluder::intersect
      vec3 e = s.a.xyz - o;
      float tc = dot(e, v);
      float d = length(e - tc * v);
      float r = s.b.w;
      if (!(d <= r)) continue;
      float hh = sqrt((r - d) * (r + d));
      float t = tc - hh;
      if (!(t > t_min && t <= h.t)) t = tc + hh;
      if (!(t > t_min && t <= h.t)) continue;
      h.t = t;
      h.n = (o + t * v - s.a.xyz) / r;
      h.material = int(s.c.w);
    } else if (kind == 0) {  // PlaneOccluder::intersect
      float denom = dot(v, s.b.xyz);
      if (denom == 0.0) continue;
      float t = dot(s.a.xyz - o, s.b.xyz) / denom;
      if (!(t > t_min && t <= h.t)) continue;
      h.t = t;
      h.n = s.b.xyz;
      h.material = int(s.c.w);
    } else {  // a seen light's hit(): front only
      vec3 n = s.d.xyz;
      float denom = dot(v, n);
      if (!(denom < 0.0)) continue;
      float t = dot(s.a.xyz - o, n) / denom;
      if (!(t > t_min && t <= h.t)) continue;
      vec3 p = o + t * v - s.a.xyz;
      float n2 = dot(n, n);
      float a = dot(cross(p, s.c.xyz), n) / n2;
      float b = dot(cross(s.b.xyz, p), n) / n2;
      if (!outline_inside(int(s.d.w), vec2(a, b))) continue;
      h.t = t;
      h.n = normalize(n);
      h.material = int(s.c.w);
    }
  }
  if (u_node_count == 0) return h;
  // (GLSL leaves x / 0 unspecified: a tiny stand-in for a zero component.)
  vec3 inv = 1.0 / mix(v, vec3(1e-20), equal(v, vec3(0.0)));
  int stack[32];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    BvhNode node = nodes[stack[--top]];
    vec3 t0 = (node.lo - o) * inv, t1 = (node.hi - o) * inv;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, t_min));
    float leave = min(min(tf.x, tf.y), min(tf.z, h.t));
    if (!(enter <= leave)) continue;
    if (node.count == 0) {
      if (top + 2 <= 32) {
        stack[top++] = node.first + 1;
        stack[top++] = node.first;
      }
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      SpecTriangle tri = tris[i];
      float facing = dot(v, tri.n.xyz);
      if (tri.e1.w > 0.5 && facing > 0.0) continue;  // one-sided, seen from behind
      // Moeller-Trumbore.
      vec3 pv = cross(v, tri.e2.xyz);
      float det = dot(tri.e1.xyz, pv);
      if (det == 0.0) continue;
      float inv_det = 1.0 / det;
      vec3 tv = o - tri.a.xyz;
      float bu = dot(tv, pv) * inv_det;
      if (bu < 0.0 || bu > 1.0) continue;
      vec3 qv = cross(tv, tri.e1.xyz);
      float bv = dot(v, qv) * inv_det;
      if (bv < 0.0 || bu + bv > 1.0) continue;
      float t = dot(tri.e2.xyz, qv) * inv_det;
      if (!(t > t_min && t <= h.t)) continue;
      h.t = t;
      h.n = tri.n.xyz;
      h.material = int(tri.a.w);
    }
  }
  return h;
}

uint cell_hash(ivec3 c) {
  return (uint(c.x) * 73856093u) ^ (uint(c.y) * 19349663u) ^ (uint(c.z) * 83492791u);
}

// splat_kernel (gi/photon_gather.cpp) for d < r.
float kernel_weight(float d, float r) {
  float area = kPi * r * r;
  if (u_kernel == 0) return 1.0 / area;
  if (u_kernel == 1) return 3.0 / area * (1.0 - d / r);
  return 2.0 / area * (1.0 - (d * d) / (r * r));
}

// PhotonGather::fixed_radius without the albedo / pi.
vec3 photon_sum(vec3 x, vec3 n) {
  vec3 sum = vec3(0.0);
  for (int g = 0; g < 2; ++g) {
    if (u_grid_mask[g] < 0) continue;
    float r = u_grid_radius[g];
    ivec3 c = ivec3(floor((x - u_grid_origin[g]) * u_grid_inv_cell[g]));
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          ivec3 cc = c + ivec3(dx, dy, dz);
          vec3 fc = vec3(cc);
          int h = u_grid_base[g] + int(cell_hash(cc) & uint(u_grid_mask[g]));
          uint end = cells[h + 1];
          for (uint i = cells[h]; i < end; ++i) {
            SpecPhoton p = photons[i];
            // Another cell's photons sharing the bucket are that cell's.
            if (vec3(p.p.w, p.n.w, p.power.w) != fc) continue;
            vec3 dp = x - p.p.xyz;
            float d = length(dp);
            if (!(d < r)) continue;
            if (dot(p.n.xyz, n) < kMinCos || abs(dot(dp, n)) > kMaxPlane * r) continue;
            sum += kernel_weight(d, r) * p.power.rgb;
          }
        }
      }
    }
  }
  return sum;
}

// LitShading::diffuse: the photon estimate plus the direct points' light.
vec3 diffuse(vec3 x, vec3 n, vec3 albedo) {
  vec3 sum = photon_sum(x, n);
  for (int i = 0; i < u_direct_count; ++i) {
    SpecDirect p = direct[i];
    vec3 to = p.p.xyz - x;
    float d = length(to);
    vec3 l = to / max(d, 1e-30);
    float cos_x = dot(n, l);
    float cl = -dot(p.axis.xyz, l);
    float angular = 1.0;
    int mode = int(p.p.w);
    if (mode == 1) {
      angular = max(cl, 0.0);
    } else if (mode == 2) {
      angular = cl >= p.flux.w ? 1.0 : cl <= p.cone.x ? 0.0 : smoothstep(p.cone.x, p.flux.w, cl);
    }
    bool lit = d > 2.0 * u_eps && cos_x > 0.0 && angular > 0.0;
    if (lit) lit = nearest(x, l, u_eps, d - u_eps).material < 0;  // else in shadow
    if (lit) sum += (p.axis.w * angular * cos_x / (d * d)) * p.flux.rgb;
  }
  return albedo / kPi * sum;
}

struct Branch {
  vec3 o;
  vec3 d;
  vec3 throughput;
  float weight;
  float t_min;
  float t_max;
  int depth;
};

// LitShading::trace, depth first over the branches.
vec3 trace(vec3 o, vec3 d, float t_min, float t_max) {
  const int kStack = kMaxDepth + 4;  // one pending sibling per depth, and the root
  Branch stack[kStack];
  int top = 0;
  stack[top++] = Branch(o, d, vec3(1.0), 1.0, t_min, t_max, 0);
  vec3 sum = vec3(0.0);
  while (top > 0) {
    Branch b = stack[--top];
    Hit h = nearest(b.o, b.d, b.t_min, b.t_max);
    if (h.material < 0) {
      sum += b.throughput * u_background;
      continue;
    }
    SpecMaterial m = materials[h.material];
    int type = int(m.albedo.w + 0.5);
    if (type == 3) {
      sum += b.throughput * m.albedo.rgb;
      continue;
    }
    bool entering = dot(b.d, h.n) <= 0.0;
    vec3 n = entering ? h.n : -h.n;
    vec3 x = b.o + h.t * b.d;
    if (type == 0) {
      sum += b.throughput * diffuse(x, n, m.albedo.rgb);
      continue;
    }
    if (b.depth >= kMaxDepth || b.weight < kMinWeight) continue;
    if (type == 1) {
      vec3 refl = m.specular.rgb;
      float w = max(refl.r, max(refl.g, refl.b));
      stack[top++] = Branch(x, reflect(b.d, n), b.throughput * refl, b.weight * w, u_eps, kFar,
                            b.depth + 1);
      continue;
    }
    // Glass: Fresnel (gi/optics.hpp) from the side the ray comes from.
    float eta_i = entering ? 1.0 : m.specular.w;
    float eta_t = entering ? m.specular.w : 1.0;
    float cos_i = -dot(b.d, n);
    float eta = eta_i / eta_t;
    float sin_t2 = eta * eta * (1.0 - cos_i * cos_i);
    float F = 1.0;
    vec3 refr = vec3(0.0);
    if (sin_t2 < 1.0) {
      float cos_t = sqrt(1.0 - sin_t2);
      float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
      float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
      F = 0.5 * (rs * rs + rp * rp);
      refr = normalize(eta * b.d + (eta * cos_i - cos_t) * n);
    }
    if (F > 0.0 && top < kStack) {
      stack[top++] = Branch(x, reflect(b.d, n), b.throughput * F, b.weight * F, u_eps, kFar,
                            b.depth + 1);
    }
    if (F < 1.0 && top < kStack) {
      vec3 tint = m.specular.rgb;
      float tw = max(tint.r, max(tint.g, tint.b));
      stack[top++] = Branch(x, refr, b.throughput * (1.0 - F) * tint, b.weight * (1.0 - F) * tw,
                            u_eps, kFar, b.depth + 1);
    }
  }
  return sum;
}

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  if (px.x >= int(cam.viewport.x) || px.y >= int(cam.viewport.y)) return;
  float material = VIEW_TEXEL(u_albedo, px).w;
  if (!(material > 0.5 && material < 2.5)) return;  // mirror (1) or glass (2)
  vec3 c = vec3(0.0);
  for (int sy = 0; sy < u_samples; ++sy) {
    for (int sx = 0; sx < u_samples; ++sx) {
      ViewRay r = view_ray(vec2(px) + (vec2(sx, sy) + 0.5) / float(u_samples));
      c += trace(u_eye + r.origin, r.dir, r.t_min, r.t_max);
    }
  }
  store(px, vec4(c / float(u_samples * u_samples), 1.0));
}
