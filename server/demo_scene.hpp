// The scene preloaded as "demo": examples/paper_10sets.json, embedded at build time.
#pragma once

namespace beamcast {
extern const char* const kDemoSceneJson;
}
