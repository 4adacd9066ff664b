// Prelude of the "volume_cast..._skip..." programs (shaders/programs.txt):
// empty-space skipping, for volumes with an empty brick (see
// volume_preint_on.glsl for why each option is a program).
#define VOLUME_SKIP 1
