// slim.evaluation "patch", before the accumulate pass's patches: the
// nearest depth (slim_near) into the pass's depth buffer, so that a patch
// whose box lies wholly behind it (beyond the depth threshold) fails the
// early depth test. Pixels no patch reaches get the near plane: nothing
// accumulates there.
layout(binding = 1) uniform VIEW_SAMPLER u_near;

void main() {
  select_view(view_index());
  float near = VIEW_TEXEL(u_near, ivec2(gl_FragCoord.xy)).r;
  gl_FragDepth = near >= 1e29 ? 1.0 : window_depth(near);
}
