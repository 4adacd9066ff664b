// SLIM pass 2 (seed 003): the points within the depth threshold behind the
// pixel's nearest point add their weighted normal, albedo and depth
// (additive blending); the rest lie on a hidden part of the surface.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;
layout(binding = 1) uniform VIEW_SAMPLER u_near;
uniform float u_threshold;  // slim.depth_threshold, in units of the point's sphere radius

in float v_weight;
in float v_depth;
in vec3 v_normal;
flat in float v_radius;
flat in vec3 v_albedo;

layout(location = 0) out vec4 out_normal;  // (w n, w)
layout(location = 1) out vec4 out_albedo;  // (w albedo, w depth)

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  if (v_depth >= VIEW_TEXEL(u_scene_depth, px).r) discard;
  if (v_depth > VIEW_TEXEL(u_near, px).r + u_threshold * v_radius) discard;
  out_normal = vec4(v_weight * v_normal, v_weight);
  out_albedo = vec4(v_weight * v_albedo, v_weight * v_depth);
}
