#include "render/pass_plan.hpp"

namespace beamcast {

const std::vector<PassRule>& pass_catalog() {
  static const std::vector<PassRule> kCatalog = {
      // Occluders: depth and shaded colour; without them the beams see no surface.
      {"surfaces", [](const Scene& s) { return !s.occluders.empty(); }},
      {"beams", [](const Scene& s) { return !s.beams.empty(); }},
      // Every frame is tone-mapped into its output format.
      {"tonemap", [](const Scene&) { return true; }},
  };
  return kCatalog;
}

std::vector<std::string> plan_passes(const Scene& scene) {
  std::vector<std::string> names;
  for (const PassRule& rule : pass_catalog()) {
    if (rule.needed(scene)) names.emplace_back(rule.name);
  }
  return names;
}

}  // namespace beamcast
