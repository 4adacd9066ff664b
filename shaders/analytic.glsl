// The analytic occluders (planes and spheres) as the GPU holds them:
// camera-relative records, view-major in a multi-view batch
// (SceneResources::fill_analytic).
struct AnalyticOccluder {
  vec4 a;       // plane: point; sphere: centre (camera-relative); w: sphere radius
  vec4 b;       // plane: unit normal; w: 0 plane, 1 sphere
  vec4 albedo;  // rgb; w: MaterialType (0 diffuse, 1 mirror, 2 glass)
};
layout(std430, binding = 2) readonly buffer Analytic { AnalyticOccluder occ[]; };
uniform int u_count;  // per view; view v's occluders start at v * u_count
