// SLIM pass 1, slim.evaluation "patch": the nearest view depth at which a
// pixel's centre ray meets a sphere's patch (MIN blending into slim_near),
// and the smallest radius of those spheres (slim_radius), as
// slim_depth.frag's field evaluation.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;

layout(location = 0) out float out_near;
layout(location = 1) out float out_radius;

void main() {
  select_view(view_index());
  float z;
  if (!patch_crossing(z)) discard;
  if (z >= VIEW_TEXEL(u_scene_depth, ivec2(gl_FragCoord.xy)).r) discard;
  out_near = z;
  out_radius = v_p2.w;
}
