// Prelude of the "volume_cast..._knots" programs (shaders/programs.txt): the
// beams' transmittance knots tracked and written (the pass "volumes" of a
// scene with beams; see volume_preint_on.glsl for why each option is a
// program).
#define VOLUME_KNOTS 1
