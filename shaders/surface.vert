// Rasterized occluders (boxes, meshes, quads): anchor-relative triangles with flat normals.
layout(location = 0) in vec3 a_position;  // relative to the mesh anchor
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_albedo;
layout(location = 3) in float a_one_sided;  // 1: visible only from the normal's side
layout(location = 4) in float a_material;   // MaterialType: 0 diffuse, 1 mirror, 2 glass

out vec3 v_position;  // camera-relative
out vec3 v_normal;
out vec3 v_albedo;
flat out float v_one_sided;
flat out float v_material;

void main() {
#ifdef BEAMCAST_MULTIVIEW
  select_view(u_view);  // this draw's view
#endif
  v_position = a_position + cam.mesh_offset.xyz;
  v_normal = a_normal;
  v_albedo = a_albedo;
  v_one_sided = a_one_sided;
  v_material = a_material;
  gl_Position = cam.view_proj * vec4(v_position, 1.0);
}
