// Rasterized occluders (boxes, meshes): anchor-relative triangles with flat normals.
layout(location = 0) in vec3 a_position;  // relative to the mesh anchor
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;

out vec3 v_position;  // camera-relative
out vec3 v_normal;
out vec3 v_albedo;

void main() {
#ifdef BEAMCAST_MULTIVIEW
  select_view(gl_InstanceID);  // one instance per view
  gl_Layer = gl_InstanceID;
#endif
  v_position = a_position + cam.mesh_offset.xyz;
  v_normal = a_normal;
  v_albedo = a_albedo;
  gl_Position = cam.view_proj * vec4(v_position, 1.0);
}
