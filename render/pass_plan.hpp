// Which passes a scene calls for, decided from its content alone (no GL), so
// the server can report a plan and tests can check it without a context.
#pragma once

#include <string>
#include <vector>

#include "protocol/scene.hpp"

namespace beamcast {

struct PassRule {
  const char* name;
  bool (*needed)(const Scene& scene);
};

// Every pass the renderer has, in execution order, with the rule that turns it on.
const std::vector<PassRule>& pass_catalog();

// The names of the passes `scene` needs, in execution order.
std::vector<std::string> plan_passes(const Scene& scene);

}  // namespace beamcast
