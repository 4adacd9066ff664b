// Shadow maps of the direct-light pass: the scene's triangles seen from one
// direct point, into one face of its cube map (render/passes.cpp, DirectPass).
layout(location = 0) in vec3 a_position;  // relative to the mesh anchor
uniform vec3 u_offset;  // mesh anchor minus the direct point
uniform mat4 u_face;    // the cube face's projection (clip w = distance along its axis)

out vec3 v_rel;  // relative to the direct point

void main() {
  v_rel = a_position + u_offset;
  gl_Position = u_face * vec4(v_rel, 1.0);
}
