// Prelude of the "photon_splat_box" and "gi_resolve_box" programs
// (shaders/programs.txt): the box kernel compiled in (SplatKernel::kBox).
// The kernel is a program, not a uniform branch: on llvmpipe the branch cost
// a fifth of the splatting (docs/gi.md).
#define GI_KERNEL 0
