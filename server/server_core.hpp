// What every session shares: configuration, scene store, render service,
// counters. Owned by Server; outlives every session.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "server/config.hpp"
#include "server/metrics.hpp"
#include "server/render_service.hpp"
#include "server/scene_store.hpp"
#include "server/stats.hpp"

namespace beamcast {

struct ServerCore {
  ServerConfig config;
  ServerStats stats;
  Metrics metrics;
  SceneStore scenes;
  std::unique_ptr<RenderService> renders;
  std::string renderer_description;
  std::atomic<bool> shutting_down{false};

  explicit ServerCore(const ServerConfig& c)
      : config(c), scenes(c.max_scenes, c.max_scene_store_bytes) {}
};

}  // namespace beamcast
