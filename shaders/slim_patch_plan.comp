// SLIM without sampling (slim.evaluation "patch"; render/slim_pass.hpp), the
// plan of one view: per support sphere the clip positions of the rectangle
// that slim_patch.vert draws next, computed once here rather than at each
// of the rectangle's 4 vertices. The rectangle faces the eye through
// the sphere's centre and bounds the patch's body, the sphere within the
// slab lo <= w <= hi of its frame (lo, hi from slim_height_range,
// protocol/slim_model.hpp). A sphere holding the eye gets the whole
// viewport. Spheres whose patch faces away from the camera get a rectangle
// outside the clip volume (as the points' CPU plan drops them with
// slim.cull_backfaces).
layout(local_size_x = 64) in;
layout(std430, binding = 8) writeonly buffer SlimPatchCorners { vec4 corners[]; };
uniform vec3 u_offset;      // slim anchor minus eye
uniform int u_count;        // spheres
uniform int u_cull_backfaces;
uniform float u_threshold;  // slim.depth_threshold

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

// Corners in a triangle strip's order: (0,0) (1,0) (0,1) (1,1) of the
// rectangle's (a, b) extent (QuadIndices, render/gl_util.hpp).
void store(int i, vec4 p0, vec4 p1, vec4 p2, vec4 p3) {
  int k = 4 * i;
  corners[k] = p0;
  corners[k + 1] = p1;
  corners[k + 2] = p2;
  corners[k + 3] = p3;
}

void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= u_count) return;
  select_view(view_index());
  SlimGpu s = spheres[i];
  vec3 c = s.center.xyz + u_offset;
  float r = s.center.w;
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
      vec4 out_of_view = vec4(2.0, 2.0, 2.0, 1.0);  // every vertex outside: nothing drawn
      store(i, out_of_view, out_of_view, out_of_view, out_of_view);
      return;
    }
  }
  if (!ortho && dist <= 1.01 * r) {
    // The eye inside the sphere: the whole viewport, at the near plane
    // (never depth-culled).
    store(i, vec4(-1.0, -1.0, 1.0, 1.0), vec4(1.0, -1.0, 1.0, 1.0), vec4(-1.0, 1.0, 1.0, 1.0),
          vec4(1.0, 1.0, 1.0, 1.0));
    return;
  }
  // A rectangle in the plane through the centre facing the eye (v), on
  // axes a (across the patch's normal n) and b, bounding the patch's body.
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
  // A rectangle reaching in front of the near plane is not cut there (its
  // window depth is set below, at or behind the near plane), and the part
  // of it that can hold the patch's projection lies in front of the eye
  // (every point of the body is at least L - r > 0 along v, and the ray to
  // it meets the plane at a point in front of the eye).
  // Its window depth is that of the body's nearest view depth less the
  // depth threshold, the same over it (z = that depth's window value times
  // w). The accumulate pass's depth test (GEQUAL, reversed Z, against
  // slim_near) then drops every fragment of a patch lying wholly beyond
  // the threshold, which the fragment would drop after its work.
  float front = dot(c, cam.cam_forward.xyz) +
                body_extent(dot(cam.cam_forward.xyz, n), r, s.q2.z, s.q2.w).x;
  float z = window_depth(max(front - (u_threshold + 1e-3) * r, cam.viewport.z));
  vec4 q[4];
  for (int k = 0; k < 4; ++k) {
    vec3 x = c + ((k & 1) == 0 ? ea.x : ea.y) * a + ((k & 2) == 0 ? eb.x : eb.y) * b;
    q[k] = cam.view_proj * vec4(x, 1.0);
    q[k].z = z * q[k].w;
  }
  store(i, q[0], q[1], q[2], q[3]);
}
