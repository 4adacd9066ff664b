// SLIM without sampling (slim.evaluation "patch"; render/slim_pass.hpp):
// instance i is support sphere i, drawn as one quad (a 4-vertex strip) that
// covers the sphere's projection; each fragment solves where its centre
// ray meets the sphere's height field (slim_crossing). Perspective: a
// square facing the eye through the centre, of half side r L / sqrt(L^2 -
// r^2) at distance L (it holds the sphere's silhouette cone); a sphere
// holding the eye or reaching the near plane gets the whole viewport.
// Spheres whose patch faces away from the camera are dropped (as the
// points' CPU plan does with slim.cull_backfaces).
uniform vec3 u_offset;  // slim anchor minus eye
uniform int u_cull_backfaces;

out float v_weight;
out float v_depth;
out vec3 v_normal;
flat out float v_radius;
flat out vec3 v_albedo;
flat out uint v_sphere;
flat out vec3 v_point;
flat out vec2 v_window;
flat out vec3 v_cell;

void main() {
  select_view(view_index());
  uint i = uint(gl_InstanceID);
  SlimGpu s = spheres[i];
  vec3 c = s.center.xyz + u_offset;
  float r = s.center.w;
  vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
  v_weight = 1.0;
  v_depth = 0.0;
  v_normal = vec3(0.0);
  v_radius = r;
  v_albedo = s.albedo.rgb;
  v_sphere = i;
  v_point = vec3(0.0);
  v_window = vec2(0.0);
  v_cell = vec3(0.0);
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
      gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // all four outside: nothing drawn
      return;
    }
  }
  vec3 p;
  if (ortho) {
    p = c + 1.01 * r * (corner.x * cam.cam_right.xyz + corner.y * cam.cam_up.xyz);
  } else {
    if (dist <= 1.01 * r) {
      gl_Position = vec4(corner, 0.0, 1.0);
      return;
    }
    vec3 axis = c / dist;
    vec3 e1 = cross(axis, cam.cam_up.xyz);
    if (dot(e1, e1) < 1e-6) e1 = cross(axis, cam.cam_right.xyz);
    e1 = normalize(e1);
    vec3 e2 = cross(e1, axis);
    float half_side = 1.01 * r * dist / sqrt(dist * dist - r * r);
    p = c + half_side * (corner.x * e1 + corner.y * e2);
    // A square reaching behind the near plane would be clipped where the
    // sphere may still be seen: the whole viewport then. The four corners
    // bound the square, so one test per corner decides.
    bool near_cut = false;
    for (int k = 0; k < 4; ++k) {
      vec2 ck = vec2(float(k & 1), float(k >> 1)) * 2.0 - 1.0;
      vec3 q = c + half_side * (ck.x * e1 + ck.y * e2);
      near_cut = near_cut || dot(q, cam.cam_forward.xyz) < cam.viewport.z;
    }
    if (near_cut) {
      gl_Position = vec4(corner, 0.0, 1.0);
      return;
    }
  }
  gl_Position = cam.view_proj * vec4(p, 1.0);
}
