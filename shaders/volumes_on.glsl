// Prelude of the beam programs "..._volumes" (shaders/programs.txt): the beam
// shader with the volumes' transmittance knots compiled in (volume_knots.glsl),
// used only for scenes with volumes, so the beam programs of every other
// scene stay as they were.
#define BEAMCAST_VOLUMES 1
