in vec3 v_position;
in vec3 v_normal;
in vec3 v_albedo;
flat in float v_one_sided;

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;

void main() {
  select_view(view_index());
  vec3 view_dir = is_orthographic() ? cam.cam_forward.xyz : normalize(v_position);
  // One-sided triangles are seen (and occlude) only from the side their normal
  // points to, like the reference's one-sided intersection.
  if (v_one_sided > 0.5 && dot(v_normal, view_dir) > 0.0) discard;
  out_color = vec4(lambert(v_albedo, normalize(v_normal), view_dir), 0.0);
  out_view_depth = dot(v_position, cam.cam_forward.xyz);
}
