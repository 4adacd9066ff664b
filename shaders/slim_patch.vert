// SLIM without sampling (slim.evaluation "patch"; render/slim_pass.hpp):
// instance i is support sphere i, drawn as one rectangle (a 4-vertex strip)
// facing the eye through the sphere's centre that bounds the patch's body,
// the sphere within the slab lo <= w <= hi of its frame (lo, hi from
// slim_height_range, protocol/slim_model.hpp). Each fragment solves where
// its centre ray meets the sphere's height field (slim_patch.glsl). A
// sphere holding the eye gets the whole viewport. Spheres whose patch faces
// away from the camera are dropped (as the points' CPU plan does with
// slim.cull_backfaces). The sphere's data goes to the fragments as flat
// varyings (no buffer reads per fragment).
uniform vec3 u_offset;  // slim anchor minus eye
uniform int u_cull_backfaces;
uniform float u_threshold;  // slim.depth_threshold

flat out vec3 v_c;             // the centre, camera-relative
flat out vec4 v_p1;            // A, B, C, D
flat out vec4 v_p2;            // E, F, crease, radius
flat out vec4 v_q1;            // the second polynomial
flat out vec2 v_q2;
flat out vec3 v_au;            // the frame's axes in world space
flat out vec3 v_av;
flat out vec3 v_aw;
flat out vec3 v_albedo;

// The least and greatest of e . x over the points x of the sphere (radius r,
// frame centred) within the slab lo <= w <= hi, for a unit direction e with
// e . n = en (n the frame's w axis): at height w the most is en w + et
// sqrt(r^2 - w^2), largest at w = r en, else at the slab's nearer side.
vec2 body_extent(float en, float r, float lo, float hi) {
  float et = sqrt(max(0.0, 1.0 - en * en));
  float w_hi = clamp(r * en, lo, hi), w_lo = clamp(-r * en, lo, hi);
  float most = en * w_hi + et * sqrt(max(0.0, r * r - w_hi * w_hi));
  float least = en * w_lo - et * sqrt(max(0.0, r * r - w_lo * w_lo));
  return vec2(least, most);
}

void main() {
  select_view(view_index());
  SlimGpu s = spheres[gl_InstanceID];
  vec3 c = s.center.xyz + u_offset;
  float r = s.center.w;
  v_p1 = s.p1;
  v_p2 = vec4(s.p2.xyz, r);
  v_q1 = s.q1;
  v_q2 = s.q2.xy;
  v_au = s.axis_u.xyz;
  v_av = s.axis_v.xyz;
  v_aw = s.axis_w.xyz;
  v_albedo = s.albedo.rgb;
  v_c = c;
  bool ortho = is_orthographic();
  float dist = length(c);
  if (u_cull_backfaces == 1 && (ortho || dist > r)) {
    // Every normal within s.p2.w (atan of the largest slope) of the local w
    // axis, every view direction to the patch within asin(r / L) of the
    // direction to the centre: all face away.
    vec3 view = ortho ? cam.cam_forward.xyz : c / dist;
    float beta = ortho ? 0.0 : asin(r / dist);
    float margin = 1.5707963 - s.p2.w - beta - 1e-3;
    if (margin > 0.0 && dot(s.axis_w.xyz, view) > cos(margin)) {
      gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // every vertex outside: nothing drawn
      return;
    }
  }
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
  // The whole viewport, unless below (at the near plane: never depth-culled).
  gl_Position = vec4(corner * 2.0 - 1.0, 1.0, 1.0);
  if (!ortho && dist <= 1.01 * r) return;            // the eye inside the sphere
  // A rectangle in the plane through the centre facing the eye (v), on
  // axes a (across the patch's normal n) and b, bounding the patch's body:
  // the sphere within the slab lo <= w <= hi of its frame.
  vec3 v = ortho ? cam.cam_forward.xyz : c / dist;
  vec3 n = s.axis_w.xyz;
  vec3 a = cross(v, n);
  if (dot(a, a) < 1e-8) a = cross(v, abs(v.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0));
  a = normalize(a);
  vec3 b = cross(v, a);
  vec2 ea = body_extent(dot(a, n), r, s.q2.z, s.q2.w);
  vec2 eb = body_extent(dot(b, n), r, s.q2.z, s.q2.w);
  if (!ortho) {
    // Seen from the eye, a point of the body at depth d along v lands in
    // the plane scaled by L / d, d within L +- r.
    float grow = dist / (dist - r), shrink = dist / (dist + r);
    ea = vec2(ea.x * (ea.x < 0.0 ? grow : shrink), ea.y * (ea.y > 0.0 ? grow : shrink));
    eb = vec2(eb.x * (eb.x < 0.0 ? grow : shrink), eb.y * (eb.y > 0.0 ? grow : shrink));
  }
  ea += vec2(-1e-3, 1e-3) * r;
  eb += vec2(-1e-3, 1e-3) * r;
  vec3 p = c + mix(ea.x, ea.y, corner.x) * a + mix(eb.x, eb.y, corner.y) * b;
  // A rectangle reaching in front of the near plane is not cut there (its
  // window depth is set below, at or behind the near plane), and the part
  // of it that can hold the patch's projection lies in front of the eye
  // (every point of the body is at least L - r > 0 along v, and the ray to
  // it meets the plane at a point in front of the eye).
  gl_Position = cam.view_proj * vec4(p, 1.0);
  // The rectangle's window depth is that of the body's nearest view depth
  // less the depth threshold, the same over it (z = that depth's window
  // value times w). The accumulate pass's depth test (GEQUAL, reversed Z,
  // against slim_near) then drops every fragment of a patch lying wholly
  // beyond the threshold, which the fragment would drop after its work.
  float front = dot(c, cam.cam_forward.xyz) +
                body_extent(dot(cam.cam_forward.xyz, n), r, s.q2.z, s.q2.w).x;
  float z = max(front - (u_threshold + 1e-3) * r, cam.viewport.z);
  gl_Position.z = window_depth(z) * gl_Position.w;
}
