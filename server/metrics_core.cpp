// The parts of server/metrics.hpp that read the server core (kept apart so
// metrics.cpp stays free of GL and sockets and unit tests can link it alone).
#include <chrono>
#include <cstdio>

#include "server/http_server.hpp"
#include "server/metrics.hpp"
#include "server/server_core.hpp"

namespace beamcast {

Metrics::Gauges sample_gauges(const ServerCore& core) {
  Metrics::Gauges g;
  const nlohmann::json st = core.stats.to_json();
  g.connections_open = core.stats.connections_open();
  g.connections_total = st["connections"]["total"].get<std::uint64_t>();
  g.frames = st["frames"].get<std::uint64_t>();
  g.bytes_out = st["bytes_out"].get<std::uint64_t>();
  g.errors = st["errors"].get<std::map<std::string, std::uint64_t>>();
  g.uptime_s = st["uptime_s"].get<double>();
  if (core.renders) {
    g.queue_depth = core.renders->queued();
    g.inflight = core.renders->inflight();
    g.renders_dropped = core.renders->dropped();
    g.renderer_rebuilds = core.renders->renderer_rebuilds();
    g.class_queue_depth = {core.renders->queued(WorkClass::kInteractive),
                           core.renders->queued(WorkClass::kBatch)};
    g.renders_cancelled = core.renders->cancelled();
    g.slices_dropped = core.renders->slices_dropped();
    g.turns = core.renders->turns_taken();
    const SceneGpuCache::Stats c = core.renders->scene_cache();
    g.scene_cache_bytes = c.bytes;
    g.scene_cache_budget_bytes = c.budget;
    g.scene_cache_entries = c.entries;
    g.scene_cache_hits = c.hits;
    g.scene_cache_misses = c.misses;
    g.scene_cache_evictions = c.evictions;
  }
  return g;
}

void log_request(const ServerCore& core, const nlohmann::json& id, const std::string& method,
                 const std::string& outcome, const nlohmann::json& timings) {
  if (!core.config.request_log) return;
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  nlohmann::json line = {{"ts", std::chrono::duration<double>(now).count()},
                         {"id", id},
                         {"method", method},
                         {"outcome", outcome}};
  if (!timings.is_null()) line["timings_ms"] = timings;
  // One write per line so lines from several threads do not interleave.
  const std::string text =
      line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::fwrite(text.data(), 1, text.size(), stderr);
}

void register_metrics_routes(HttpServer& http, ServerCore& core) {
  http.add_get("/metrics", [&core] {
    return HttpReply{200, "text/plain; version=0.0.4; charset=utf-8",
                     core.metrics.prometheus(sample_gauges(core))};
  });
  http.add_get("/health", [&core] {
    const bool draining = core.shutting_down.load();
    const nlohmann::json h = health_json(draining, sample_gauges(core), core.renderer_description);
    return HttpReply{draining ? 503 : 200, "application/json", h.dump() + "\n"};
  });
}

}  // namespace beamcast
