// Prelude of the program "direct_light_lean" (direct_light.frag without the
// analytic occluders' shadow rays and the medium's attenuation): scenes with
// neither.
#define BEAMCAST_DIRECT_LEAN 1
