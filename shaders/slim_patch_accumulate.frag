// SLIM pass 2, slim.evaluation "patch": each sphere holding x1 (the
// nearest depth on the centre ray) or x2 (a step behind) whose surface
// passes within the depth threshold of it (|h| there, in the sphere's
// radii) adds its terms of F at x1 and x2, as slim_accumulate.frag's field
// evaluation. (The field's points test their crossing along the ray
// instead; the height, which the terms compute anyway, spares solving for
// the crossing again and differs only for supports seen edge-on.)
// The patch's box is culled by the depth test against slim_near (slim_zbuf,
// slim_near_depth.frag) before this runs. (x1 lies in front of the scene's
// other surfaces: the depth pass kept only crossings in front of them.)
layout(early_fragment_tests) in;
layout(binding = 1) uniform VIEW_SAMPLER u_near;
layout(binding = 2) uniform VIEW_SAMPLER u_radius;
uniform float u_threshold;  // slim.depth_threshold, in units of the sphere's radius

layout(location = 0) out vec4 out_albedo;  // (w(x1) albedo, 0)
layout(location = 1) out vec4 out_field;   // (w grad h + h grad w, w h) at x1
layout(location = 2) out vec4 out_weight;  // (grad w, w) at x1
layout(location = 3) out vec4 out_field2;  // the same at x2
layout(location = 4) out vec4 out_weight2;

void main() {
  select_view(view_index());
  ivec2 px = ivec2(gl_FragCoord.xy);
  float near = VIEW_TEXEL(u_near, px).r;
  if (near >= 1e29) discard;  // no patch reaches this pixel
  patch_ray();
  float step = slim_field_step(near, VIEW_TEXEL(u_radius, px).r);
  vec4 t1, t2, t3, t4;
  bool in1 = patch_terms(ray_org + near * ray_dir, t1, t2);
  bool in2 = patch_terms(ray_org + (near + step) * ray_dir, t3, t4);
  if (!in1 && !in2) discard;
  // A hidden layer: this sphere's surface passes farther than the
  // threshold (in its radii) from the nearest point, |h| there (w h / w),
  // or from the second point where the first is outside the sphere.
  vec2 hw = in1 ? vec2(t1.w, t2.w) : vec2(t3.w, t4.w);
  if (abs(hw.x) > u_threshold * v_p2.w * hw.y) discard;
  out_albedo = vec4(t2.w * v_albedo, 0.0);
  out_field = t1;
  out_weight = t2;
  out_field2 = t3;
  out_weight2 = t4;
}
