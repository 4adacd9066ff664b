// Prelude of the vertex stage of the programs "volume_splat" and
// "volume_splat_regions" (shaders/programs.txt): photon_splat.vert with the
// volume photons' outputs (local phase and extinction, capped radius).
#define BEAMCAST_VOLUME_PHOTONS 1
