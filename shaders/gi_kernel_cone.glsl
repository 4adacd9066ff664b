// Prelude of the "photon_splat_cone" and "gi_resolve_cone" programs
// (shaders/programs.txt): the cone kernel compiled in (SplatKernel::kCone;
// see gi_kernel_box.glsl for why).
#define GI_KERNEL 1
