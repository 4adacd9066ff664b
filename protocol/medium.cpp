#include "protocol/medium.hpp"

#include <span>
#include <string>

#include "protocol/json_reader.hpp"

namespace beamcast {

using namespace json_read;

double schlick_k_from_g(double g) { return 1.55 * g - 0.55 * g * g * g; }

Medium parse_medium(const Node& n) {
  ObjectReader o(n, "a medium");
  o.allow_only(std::span<const std::string_view>(kMediumFields));
  Medium m;
  // Up to 1e6 per unit length: optical depth 1 over a micrometre of a
  // metre-sized scene; above it a float's e^(-sigma t) is 0 everywhere.
  constexpr double kMaxCoefficient = 1e6;
  if (auto v = o.optional("sigma_s")) m.sigma_s = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  if (auto v = o.optional("sigma_a")) m.sigma_a = check_closed(*v, read_number(*v), 0.0, kMaxCoefficient);
  const auto k = o.optional("k");
  const auto g = o.optional("g");
  if (k && g) {
    fail("invalid_value", g->path,
         "give the phase function as k (Schlick) or as g (Henyey-Greenstein), not both");
  }
  if (k) m.k = check_open(*k, read_number(*k), -1.0, 1.0);
  if (g) m.k = schlick_k_from_g(check_closed(*g, read_number(*g), -kSchlickMaxG, kSchlickMaxG));
  if (auto v = o.optional("beam_rule")) {
    m.beam_rule = read_enum<BeamMediumRule>(
        *v, {{"gauss2", BeamMediumRule::kGauss2}, {"midpoint", BeamMediumRule::kMidpoint}});
  }
  // Below 0.05 a piece of optical depth 1.6 already needs every one of the
  // kMaxBeamSubPieces; above 8 one sub-piece spans e^-8 of attenuation.
  if (auto v = o.optional("beam_step")) m.beam_step = check_closed(*v, read_number(*v), 0.05, 8.0);
  if (auto v = o.optional("estimator")) {
    m.estimator = read_enum<VolumeEstimator>(
        *v, {{"beam", VolumeEstimator::kBeam}, {"seed", VolumeEstimator::kSeed}});
  }
  if (auto v = o.optional("radius")) m.radius = check_closed(*v, read_number(*v), 0.0, 1e6);
  return m;
}

}  // namespace beamcast
