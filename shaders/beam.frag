// Energy of one beam along the view ray, from the line-integral table.
//
// Units: energy = (1/r) * integral of f(dist / r) dt, path length in radii.
// Sphere (centre A): t_c = (A - o).v, d = |(A - o) x v|, s(t) = (t - t_c)/r + 1,
//   E = g(d/r, s(t1)) - g(d/r, s(t0)).
// Cylinder (point A, unit axis w): c = w x v, sin(theta) = |c|, c^ = c/|c|,
//   d = |(o - A).c^|, s(t) = (sin(theta) t + ((w x (o - A)).c^)) / r + 1,
//   E = [g(d/r, s(t1)) - g(d/r, s(t0))] / sin(theta)
// (docs/beam-math.md derives both; the paper's eq 2.8/2.9 are wrong).
// Where the s-interval is under about a texel (rays near-parallel to the axis)
// the table difference divided by sin(theta) amplifies interpolation error, so
// a 3-point Gauss rule on the 1D table of f takes over, blended smoothly.

struct BeamData {
  vec4 p0_radius;
  vec4 axis_length;
  vec4 color_layer;
  vec4 caps_kind;
};
layout(std430, binding = 1) readonly buffer Beams { BeamData beams[]; };

layout(binding = 0) uniform sampler2DArray u_g;  // g(d, s): x = s, y = d, layer = density
layout(binding = 1) uniform sampler1DArray u_f;  // f(x), layer = density
layout(binding = 2) uniform sampler2D u_view_depth;  // surfaces' view depth (huge: none)
uniform ivec3 u_table_size;  // nd, ns, nf
uniform int u_has_surfaces;

flat in int v_beam;
layout(location = 0) out vec4 out_energy;

float g_lookup(float d, float s, float layer) {
  // Texel centres hold the grid values: d_i = i/(nd-1), s_j = 2j/(ns-1).
  vec2 n = vec2(u_table_size.y, u_table_size.x);
  vec2 uv = (vec2(clamp(s, 0.0, 2.0) * 0.5, clamp(d, 0.0, 1.0)) * (n - 1.0) + 0.5) / n;
  return texture(u_g, vec3(uv, layer)).r;
}

float f_lookup(float x, float layer) {
  if (x >= 1.0) return 0.0;
  float n = float(u_table_size.z);
  return texture(u_f, vec2((x * (n - 1.0) + 0.5) / n, layer)).r;
}

float sphere_energy(vec3 o, vec3 v, vec3 center, float r, float t0, float t1, float layer) {
  if (!(t1 > t0)) return 0.0;
  vec3 to_c = center - o;
  float tc = dot(to_c, v);
  float d = length(cross(to_c, v)) / r;
  if (d >= 1.0) return 0.0;
  return g_lookup(d, (t1 - tc) / r + 1.0, layer) - g_lookup(d, (t0 - tc) / r + 1.0, layer);
}

float cylinder_energy(vec3 o, vec3 v, vec3 a, vec3 w, float r, float t0, float t1,
                      float layer) {
  if (!(t1 > t0)) return 0.0;
  vec3 m = o - a;
  vec3 c = cross(w, v);
  float sin_t = length(c);
  float dt = t1 - t0;
  float ds = sin_t * dt / r;
  float texel = 2.0 / float(u_table_size.y - 1);
  float alpha = smoothstep(0.5 * texel, texel, ds);
  float e = 0.0;
  if (alpha > 0.0) {
    vec3 ch = c / sin_t;
    float d = abs(dot(m, ch)) / r;
    if (d < 1.0) {
      float q = dot(cross(w, m), ch);
      float s0 = (sin_t * t0 + q) / r + 1.0;
      float s1 = (sin_t * t1 + q) / r + 1.0;
      e += alpha * (g_lookup(d, s1, layer) - g_lookup(d, s0, layer)) / sin_t;
    }
  }
  if (alpha < 1.0) {
    // Gauss-Legendre, 3 nodes on [t0, t1]; rho measured directly to the axis.
    const float xk[3] = float[3](-0.7745966692414834, 0.0, 0.7745966692414834);
    const float wk[3] = float[3](0.5555555555555556, 0.8888888888888888, 0.5555555555555556);
    float sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      float t = t0 + dt * 0.5 * (1.0 + xk[k]);
      float rho = length(cross(m + t * v, w)) / r;
      sum += wk[k] * f_lookup(rho, layer);
    }
    e += (1.0 - alpha) * 0.5 * dt / r * sum;
  }
  return e;
}

// Restricts [t0, t1] to the part of the ray where u(t) = u0 + t du is >= lo
// (above = true) or <= hi (above = false).
void clip_plane(float u0, float du, float bound, bool above, inout float t0, inout float t1) {
  if (du == 0.0) {
    bool inside = above ? (u0 >= bound) : (u0 <= bound);
    if (!inside) t1 = t0;
    return;
  }
  float t = (bound - u0) / du;
  bool entering = above == (du > 0.0);  // crossing the plane into the allowed side
  if (entering) {
    t0 = max(t0, t);
  } else {
    t1 = min(t1, t);
  }
}

void main() {
  BeamData b = beams[v_beam];
  ViewRay ray = view_ray(gl_FragCoord.xy);
  float t0 = ray.t_min;
  float t1 = ray.t_max;
  if (u_has_surfaces != 0) {
    float z = texelFetch(u_view_depth, ivec2(gl_FragCoord.xy), 0).r;
    t1 = min(t1, z / ray.cos_axis);
  }
  float r = b.p0_radius.w;
  float layer = b.color_layer.w;
  vec3 p0 = b.p0_radius.xyz;
  float e;
  if (b.caps_kind.z < 0.5) {
    e = sphere_energy(ray.origin, ray.dir, p0, r, t0, t1, layer);
  } else {
    vec3 w = b.axis_length.xyz;
    float len = b.axis_length.w;
    float u0 = dot(ray.origin - p0, w);
    float du = dot(ray.dir, w);
    // Cylinder: 0 <= u <= len.
    float ca = t0, cb = t1;
    clip_plane(u0, du, 0.0, true, ca, cb);
    clip_plane(u0, du, len, false, ca, cb);
    e = cylinder_energy(ray.origin, ray.dir, p0, w, r, ca, cb, layer);
    if (b.caps_kind.x > 0.5) {  // hemisphere beyond p0: u <= 0
      float sa = t0, sb = t1;
      clip_plane(u0, du, 0.0, false, sa, sb);
      e += sphere_energy(ray.origin, ray.dir, p0, r, sa, sb, layer);
    }
    if (b.caps_kind.y > 0.5) {  // hemisphere beyond p1: u >= len
      float sa = t0, sb = t1;
      clip_plane(u0, du, len, true, sa, sb);
      e += sphere_energy(ray.origin, ray.dir, p0 + len * w, r, sa, sb, layer);
    }
  }
  out_energy = vec4(b.color_layer.rgb * max(e, 0.0), 0.0);
}
