// SLIM pass 1 (seed 003): the nearest view depth per pixel (MIN blending
// into slim_near); points behind a nearer occluder are dropped.
// slim.evaluation "blend" (the seed's): the depth of the nearest point in
// the pixel. "field" (u_field = 1): the nearest depth at which the pixel's
// centre ray meets a sphere's own height field, from the points that own
// that crossing (slim_owner): the surface layer the field is evaluated on;
// and the smallest radius of those spheres (slim_radius): the scale over
// which F bends, which bounds the accumulate pass's step along the ray.
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;
uniform int u_field;
uniform vec3 u_offset;  // slim anchor minus eye

in float v_depth;
in vec3 v_normal;
flat in float v_radius;
flat in uint v_sphere;
flat in vec3 v_point;
flat in vec3 v_cell;

layout(location = 0) out float out_near;
layout(location = 1) out float out_radius;  // field: the smallest owning sphere's radius (MIN)

void main() {
  select_view(view_index());
  float depth = v_depth;
  if (u_field == 1) {
    SlimGpu s = spheres[v_sphere];
    ViewRay ray = view_ray(gl_FragCoord.xy);
    float t;
    if (!slim_owner(s, s.center.xyz + u_offset, ray, v_point, v_normal, v_cell, t)) discard;
    depth = t * ray.cos_axis;
    if (depth < cam.viewport.z) discard;  // before the near plane
  }
  if (depth >= VIEW_TEXEL(u_scene_depth, ivec2(gl_FragCoord.xy)).r) discard;
  out_near = depth;
  out_radius = v_radius;
}
