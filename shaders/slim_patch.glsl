// slim.evaluation "patch": the fragment side of slim_patch.vert. The
// pixel's centre ray in the sphere's frame is x(z) = ray_org + z ray_dir, z the
// view depth; where it first meets the sphere's height field inside the
// sphere, in closed form, and the sphere's terms of F on it.
flat in vec4 v_p1;
flat in vec4 v_p2;
flat in vec4 v_q1;
flat in vec2 v_q2;
flat in vec3 v_au;
flat in vec3 v_av;
flat in vec3 v_aw;
flat in vec3 v_albedo;
flat in vec3 v_c;

// The pixel's centre ray in the sphere's frame: origin relative to the
// centre, direction scaled to unit view depth (view_point's; computed per
// fragment: interpolating them from the vertices as noperspective varyings
// lost pixels where llvmpipe clips large quads, at zoom 4 and 16).
vec3 ray_org, ray_dir;
void patch_ray() {
  vec2 ndc = 2.0 * gl_FragCoord.xy / cam.viewport.xy - 1.0;
  vec3 across = ndc.x * cam.cam_up.w * cam.cam_right.xyz + ndc.y * cam.cam_up.xyz;
  bool ortho = is_orthographic();
  vec3 org = ortho ? cam.cam_right.w * across : vec3(0.0);
  vec3 dir = ortho ? cam.cam_forward.xyz : cam.cam_forward.xyz + cam.cam_right.w * across;
  vec3 o = org - v_c;
  ray_org = vec3(dot(o, v_au), dot(o, v_av), dot(o, v_aw));
  ray_dir = vec3(dot(dir, v_au), dot(dir, v_av), dot(dir, v_aw));
}

// The first root x in (max(-half_chord, lo), half_chord) of w - f(u, v)
// along m + x d, f polynomial (p, e): -(a x^2 + b x + q) with a = f's
// second-order part along d, b = grad f(m) . d - d_w, q = f(m) - m_w, its
// roots from the cancellation-free pair. On a crease (crease 1 min, 2
// max; the "_creases" programs, SLIM_CREASES, draw those spheres) a root
// counts where the min/max rule takes this polynomial (the other one:
// (po, eo)). 1e30 if none.
float patch_root(vec4 p, vec4 e, vec3 m, vec3 d, float half_chord, float lo, vec4 po, vec4 eo,
                 float crease) {
  vec2 g;
  float fm = poly(p, e, m.xy, g);
  float a = p.x * d.x * d.x + p.y * d.x * d.y + p.z * d.y * d.y;
  float b = dot(g, d.xy) - d.z;
  float q = fm - m.z;
  float x1 = 1e30, x2 = 1e30;
  if (abs(a) * half_chord <= 1e-6 * abs(b)) {
    x1 = -q / b;  // linear along the ray
  } else {
    float disc = b * b - 4.0 * a * q;
    if (disc >= 0.0) {
      float k = -0.5 * (b + (b < 0.0 ? -sqrt(disc) : sqrt(disc)));
      x1 = k / a;
      x2 = k != 0.0 ? q / k : 1e30;
    }
  }
  float lo_x = max(-half_chord, lo);
#ifdef SLIM_CREASES
  for (int i = 0; i < 2; ++i) {
    float x = i == 0 ? min(x1, x2) : max(x1, x2);
    if (!(x > lo_x && x < half_chord)) continue;
    vec3 l = m + x * d;
    vec2 go;
    float fo = poly(po, eo, l.xy, go);
    if (crease < 1.5 ? fo < l.z : fo > l.z) continue;  // the other polynomial holds there
    return x;
  }
  return 1e30;
#else
  float first = min(x1, x2), second = max(x1, x2);
  return first > lo_x && first < half_chord ? first
         : second > lo_x && second < half_chord ? second : 1e30;
#endif
}

// The view depth z where the ray first meets the patch beyond the near
// plane; false if it does not inside the sphere.
bool patch_crossing(out float z) {
  patch_ray();
  z = 0.0;
  float r = v_p2.w;
  float dd = dot(ray_dir, ray_dir);
  float zc = -dot(ray_org, ray_dir) / dd;  // the ray's closest approach to the centre
  vec3 m = ray_org + zc * ray_dir;
  float d2 = dot(m, m);
  if (d2 >= r * r) return false;
  float half_chord = sqrt((r * r - d2) / dd);
  float lo = cam.viewport.z - zc;
  vec4 e = vec4(v_p2.xy, 0.0, 0.0);
  float x = patch_root(v_p1, e, m, ray_dir, half_chord, lo, v_q1, vec4(v_q2, 0.0, 0.0), v_p2.z);
#ifdef SLIM_CREASES
  x = min(x, patch_root(v_q1, vec4(v_q2, 0.0, 0.0), m, ray_dir, half_chord, lo, v_p1, e, v_p2.z));
#endif
  if (x >= 1e29) return false;
  z = zc + x;
  return true;
}

vec3 patch_to_world(vec3 v) { return v.x * v_au + v.y * v_av + v.z * v_aw; }

// The sphere's terms of F at x (its frame): (w grad h + h grad w, w h) and
// (grad w, w), world space, as slim_accumulate.frag's field_terms.
bool patch_terms(vec3 x, out vec4 field, out vec4 weight) {
  field = vec4(0.0);
  weight = vec4(0.0);
  float r = v_p2.w;
  float q = 1.0 - dot(x, x) / (r * r);
  if (q <= 0.0) return false;
  vec2 gf;
#ifdef SLIM_CREASES
  float h = x.z - crease_height(v_p1, v_p2, v_q1, vec4(v_q2, 0.0, 0.0), x.xy, gf);
#else
  float h = x.z - poly(v_p1, v_p2, x.xy, gf);
#endif
  float w = q * q * q;
  vec3 gw = (-6.0 * q * q / (r * r)) * x;
  field = vec4(patch_to_world(w * vec3(-gf, 1.0) + h * gw), w * h);
  weight = vec4(patch_to_world(gw), w);
  return true;
}
