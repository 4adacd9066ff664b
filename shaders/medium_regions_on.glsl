// Prelude of the "<name>_regions" programs (shaders/programs.txt): the
// regions of medium compiled in (medium_regions.glsl).
#define BEAMCAST_MEDIUM_REGIONS 1
