// SLIM pass 1 (seed 003): the nearest point's view depth per pixel (MIN
// blending into slim_near); points behind a nearer occluder are dropped.
// With slim.evaluation "field" (u_centre_depth = 1) also the nearest depth
// at the pixel's centre (slim_centre): a point gives the view
// depth where the pixel's centre ray meets its sphere's own height field
// (two Newton steps from the crossing of the point's tangent plane; the
// point's own depth where they do not settle or the ray runs within ~6
// degrees of the plane): the field is evaluated at the nearest of these,
// which lies on the surface up to how much the spheres disagree, rather
// than up to the surface's slope over the pixel (the near edge of a pixel
// that sees the surface at a grazing angle).
layout(binding = 0) uniform VIEW_SAMPLER u_scene_depth;
uniform int u_centre_depth;
uniform vec3 u_offset;  // slim anchor minus eye

in float v_weight;
in float v_depth;
in vec3 v_normal;
flat in float v_radius;
flat in vec3 v_albedo;
flat in uint v_sphere;
flat in vec3 v_point;
flat in vec2 v_window;
flat in vec3 v_cell;

layout(location = 0) out float out_near;
layout(location = 1) out float out_centre;

void main() {
  select_view(view_index());
  if (v_depth >= VIEW_TEXEL(u_scene_depth, ivec2(gl_FragCoord.xy)).r) discard;
  out_near = v_depth;
  float depth = v_depth;
  if (u_centre_depth == 1) {
    ViewRay ray = view_ray(gl_FragCoord.xy);
    float dn = dot(ray.dir, v_normal);
    if (abs(dn) > 0.1) {
      float t = dot(v_point - ray.origin, v_normal) / dn;
      SlimGpu s = spheres[v_sphere];
      vec3 o = ray.origin - (s.center.xyz + u_offset);
      vec3 dl = vec3(dot(ray.dir, s.axis_u.xyz), dot(ray.dir, s.axis_v.xyz), dot(ray.dir, s.axis_w.xyz));
      vec3 ol = vec3(dot(o, s.axis_u.xyz), dot(o, s.axis_v.xyz), dot(o, s.axis_w.xyz));
      float h = 0.0;
      for (int k = 0; k < 2; ++k) {
        vec3 l = ol + t * dl;
        vec2 gf;
        h = l.z - height(s, l.xy, gf);
        float slope = dl.z - dot(gf, dl.xy);
        if (abs(slope) < 0.05) break;
        t -= h / slope;
      }
      // The centre lies within ~0.7 pixel of the point: where its sphere's
      // surface is steeper than ~3 (or a crease's other face takes over) the
      // extrapolation stops two pixel footprints from the point's depth.
      float footprint = 2.0 * cam.cam_right.w / cam.viewport.y * (is_orthographic() ? 1.0 : v_depth);
      depth = clamp(t * ray.cos_axis, v_depth - 2.0 * footprint, v_depth + 2.0 * footprint);
    }
  }
  out_centre = depth;
}
