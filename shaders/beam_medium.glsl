// Prelude of the program "beam_medium" (shaders/programs.txt): the beam
// shader with a medium's attenuation compiled in (beam_math.glsl), used only
// for scenes with a medium, so the medium-free program stays as it was.
#define BEAMCAST_MEDIUM 1
