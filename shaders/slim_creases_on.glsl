// Prelude of the patch programs "..._creases" (shaders/programs.txt): the
// crease rule (the min/max of a sphere's two polynomials) compiled in, for
// the spheres that have one (SlimResources::crease_begin()); the programs
// without it draw the rest.
#define SLIM_CREASES 1
