// The grid estimate's binning (pass "volume_grid", render/volume_grid.hpp):
// one invocation per cell sums the light its volume photons (sorted by
// cell, once per scene) scatter towards the eye,
//   sum p(mu) power / (share x cell volume),   mu = dot(travel, to the eye)
// (gi/phase.hpp's convention, as shaders/volume_splat.frag), with Schlick's
// phase at each photon's own k. Per view: mu looks at that view's eye.
// No atomics: a cell only reads its own photons.
layout(local_size_x = 64) in;
struct GridPhoton {
  vec4 position;  // xyz: relative to the grid's origin; w: Schlick k
  vec4 power;     // rgb: flux
  vec4 dir;       // xyz: travel direction; w: index in the volume map (uint bits)
};
layout(std430, binding = 3) readonly buffer GridPhotons { GridPhoton photons[]; };
layout(std430, binding = 4) readonly buffer GridStarts { uint starts[]; };
layout(rgba32f, binding = 0) writeonly uniform image3D u_grid;
uniform ivec3 u_dims;
uniform vec3 u_offset;     // grid origin minus eye
uniform vec3 u_ortho_dir;  // orthographic: the direction to the eye (-forward); perspective: 0
uniform int u_drawn;       // photons of index below this count (gi.display_fraction)
uniform float u_scale;     // 1 / (share x cell volume)

const float kPi = 3.14159265358979;

void main() {
  int cell = int(gl_GlobalInvocationID.x);
  if (cell >= u_dims.x * u_dims.y * u_dims.z) return;
  ivec3 at = ivec3(cell % u_dims.x, (cell / u_dims.x) % u_dims.y, cell / (u_dims.x * u_dims.y));
  bool ortho = dot(u_ortho_dir, u_ortho_dir) > 0.0;
  vec3 sum = vec3(0.0);
  for (uint i = starts[cell]; i < starts[cell + 1]; ++i) {
    GridPhoton p = photons[i];
    if (int(floatBitsToUint(p.dir.w)) >= u_drawn) continue;
    vec3 c = p.position.xyz + u_offset;  // camera-relative
    float len = length(c);
    vec3 to_eye = ortho ? u_ortho_dir : (len > 0.0 ? -c / len : -p.dir.xyz);
    float k = p.position.w;
    float q = 1.0 - k * dot(p.dir.xyz, to_eye);
    sum += p.power.rgb * ((1.0 - k * k) / (4.0 * kPi * q * q));
  }
  imageStore(u_grid, at, vec4(sum * u_scale, 0.0));
}
