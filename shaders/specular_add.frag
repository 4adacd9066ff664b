// The radiance the CPU found through mirror and glass pixels (pass
// "specular", render/specular_pass.hpp), added to hdr where it was computed.
layout(binding = 0) uniform VIEW_SAMPLER u_specular;

layout(location = 0) out vec4 out_color;

void main() {
  select_view(view_index());
  vec4 s = VIEW_TEXEL(u_specular, ivec2(gl_FragCoord.xy));
  if (s.w == 0.0) discard;
  out_color = vec4(s.rgb, 0.0);
}
