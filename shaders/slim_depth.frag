// SLIM pass 1 (seed 003): the nearest point's view depth per pixel (MIN
// blending into slim_near); points behind a nearer occluder are dropped.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;

in float v_weight;
in float v_depth;
in vec3 v_normal;
flat in float v_radius;
flat in vec3 v_albedo;

layout(location = 0) out float out_near;

void main() {
  select_view(view_index());
  if (v_depth >= VIEW_TEXEL(u_scene_depth, ivec2(gl_FragCoord.xy)).r) discard;
  out_near = v_depth;
}
