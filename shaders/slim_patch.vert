// SLIM without sampling (slim.evaluation "patch"; render/slim_pass.hpp):
// quad i (QuadIndices, render/gl_util.hpp) is support sphere i, the
// rectangle bounding its patch that slim_patch_plan.comp placed for this
// view just before. Each fragment solves where its centre ray meets the sphere's height
// field (slim_patch.glsl). The sphere's data goes to the fragments as flat
// varyings (no buffer reads per fragment).
layout(std430, binding = 8) readonly buffer SlimPatchCorners { vec4 corners[]; };
uniform vec3 u_offset;      // slim anchor minus eye

flat out vec3 v_c;             // the centre, camera-relative
flat out vec4 v_p1;            // A, B, C, D
flat out vec4 v_p2;            // E, F, crease, radius
flat out vec4 v_q1;            // the second polynomial
flat out vec2 v_q2;
flat out vec3 v_au;            // the frame's axes in world space
flat out vec3 v_av;
flat out vec3 v_aw;
flat out vec3 v_albedo;

void main() {
  SlimGpu s = spheres[gl_VertexID >> 2];
  v_c = s.center.xyz + u_offset;
  v_p1 = s.p1;
  v_p2 = vec4(s.p2.xyz, s.center.w);
  v_q1 = s.q1;
  v_q2 = s.q2.xy;
  v_au = s.axis_u.xyz;
  v_av = s.axis_v.xyz;
  v_aw = s.axis_w.xyz;
  v_albedo = s.albedo.rgb;
  gl_Position = corners[gl_VertexID];
}
