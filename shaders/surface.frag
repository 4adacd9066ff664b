in vec3 v_position;
in vec3 v_normal;
in vec3 v_albedo;
flat in float v_one_sided;
flat in float v_material;  // MaterialType, or 3: an emitter (a quad light of a lit scene)

layout(location = 0) out vec4 out_color;
layout(location = 1) out float out_view_depth;
// The G-buffer of lit scenes (pass "gbuffer"; ignored by "surfaces").
layout(location = 2) out vec4 out_normal;
layout(location = 3) out vec4 out_albedo;
uniform int u_gi;  // 1: G-buffer pass (no directional light)

void main() {
  select_view(view_index());
  vec3 view_dir = is_orthographic() ? cam.cam_forward.xyz : normalize(v_position);
  // One-sided triangles are seen (and occlude) only from the side their normal
  // points to, like the reference's one-sided intersection.
  if (v_one_sided > 0.5 && dot(v_normal, view_dir) > 0.0) discard;
  vec3 n = normalize(v_normal);
  out_view_depth = dot(v_position, cam.cam_forward.xyz);
  if (u_gi == 1) {
    // Material 3: a quad light, whose "albedo" is its emitted radiance.
    out_color = v_material > 2.5 ? vec4(v_albedo, 0.0) : vec4(0.0);
    out_normal = vec4(dot(n, view_dir) > 0.0 ? -n : n, 0.0);
    out_albedo = vec4(v_albedo, v_material);
    return;
  }
  out_color = vec4(lambert(v_albedo, n, view_dir), 0.0);
}
