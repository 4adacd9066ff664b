// The render fuzzer's structure-aware generator (docs/fuzzing.md, "The render
// fuzzer"): case i is a pure function of i. Every case is one or more
// requests of the wire protocol whose scenes have the format's shapes (every
// beam, occluder, light, medium, volume, SLIM and camera kind, with the knobs
// of gi, render, output, volume and slim), filled with numbers drawn from
// ordinary ranges and, per case at a chosen rate, from extremes: zeros,
// subnormals, 1e-300 .. 1e300, the limits' edges; and near-degenerate
// geometry (almost parallel edges, zero-length vectors, coincident points,
// slabs, dense media, tiny and huge radii).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace beamcast::render_fuzz {

struct FuzzCase {
  std::uint64_t seed = 0;
  // Sent in order on one connection; the last one's reply (all of a streamed
  // render's parts) is what the case is judged by, the earlier ones (a
  // scene.put) must be answered with ok or an error with a code and a path.
  std::vector<nlohmann::json> requests;
};

// Case `seed` (deterministic on every platform: its own PRNG and
// distributions, no std:: distributions).
FuzzCase make_case(std::uint64_t seed);

}  // namespace beamcast::render_fuzz
