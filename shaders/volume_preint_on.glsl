// Prelude of the "volume_cast_preint..." programs (shaders/programs.txt):
// steps pre-integrated (VolumeIntegration, render/volume_pass.hpp). Each
// option of the volume march is its own program, not a uniform branch: on
// llvmpipe a branch never taken still costs its share of every pixel.
#define VOLUME_PREINTEGRATED 1
