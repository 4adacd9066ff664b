// What every session shares: configuration, scene store, render service,
// counters. Owned by Server; outlives every session.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "server/config.hpp"
#include "server/memory.hpp"
#include "server/metrics.hpp"
#include "server/render_service.hpp"
#include "server/scene_store.hpp"
#include "server/stats.hpp"
#include "server/threads.hpp"

namespace beamcast {

struct ServerCore {
  ServerConfig config;
  ServerStats stats;
  Metrics metrics;
  SceneStore scenes;
  MemoryBudget request_memory;  // max_request_memory_bytes
  std::unique_ptr<RenderService> renders;
  // Handles the messages whose scene reads asset files (mesh, SLIM, volume
  // files: parsing one takes up to a second), off the network threads
  // (handle_message); null: they are handled where they arrive.
  std::unique_ptr<WorkPool> loaders;
  // Messages handed to `loaders` and not yet handled: shutdown's drain waits
  // for them as for renders in flight.
  std::atomic<int> loading{0};
  std::string renderer_description;
  std::atomic<bool> shutting_down{false};
  // Nanoseconds the network threads have spent handling messages (parsing,
  // validating, answering): MessageClock leaves it out of read_timeout_ms.
  std::atomic<std::int64_t> handling_ns{0};

  explicit ServerCore(const ServerConfig& c)
      : config(c),
        scenes(c.max_scenes, c.max_scene_store_bytes),
        request_memory(c.max_request_memory_bytes) {}
};

// The read_timeout_ms of one message counts only time spent waiting for its
// bytes, not the time the network threads spent handling other messages
// meanwhile (their share, with several threads): on one network thread,
// parsing a 13 MB request takes about a second, and twelve sent at once used
// to time each other out.
class MessageClock {
 public:
  using Clock = std::chrono::steady_clock;
  void start(const ServerCore& core) {
    deadline_ = Clock::now() + std::chrono::milliseconds(core.config.read_timeout_ms);
    handled_at_start_ = core.handling_ns.load();
  }
  // The deadline, moved on by the server's handling time since start().
  Clock::time_point deadline(const ServerCore& core) const {
    const std::int64_t stall =
        (core.handling_ns.load() - handled_at_start_) / std::max(1, core.config.network_threads);
    return deadline_ + std::chrono::nanoseconds(stall);
  }

 private:
  Clock::time_point deadline_{};
  std::int64_t handled_at_start_ = 0;
};

}  // namespace beamcast
