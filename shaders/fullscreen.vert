// One triangle that covers the viewport; no vertex buffer needed.
void main() {
#ifdef BEAMCAST_MULTIVIEW
  gl_Layer = gl_InstanceID;  // one instance per view
#endif
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
