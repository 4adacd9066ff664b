// Server metrics in the Prometheus text exposition format (version 0.0.4):
// requests by method and outcome, errors by code, per-stage latency histograms
// (queue, render, encode, total), GPU time, frames and bytes, plus gauges the
// caller samples (queue depth, in flight, connections). Thread-safe; methods
// and codes are bounded sets chosen by the server, never client strings.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

namespace beamcast {

class Metrics {
 public:
  enum Stage { kQueue, kRender, kEncode, kTotal, kStageCount };
  // Upper bounds (seconds) of the latency histogram buckets; +Inf is implied.
  static constexpr std::array<double, 14> kBuckets = {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1,
                                                      0.25,  0.5,    1.0,   2.5,  5.0,   10.0, 30.0};

  void count_request(const std::string& method, bool ok);
  void observe(Stage stage, double ms);
  void add_gpu_ms(double ms);
  // Queue wait of a render by scheduling class (WorkClass: 0 interactive,
  // 1 batch): from its arrival until its first slice reached a render worker.
  static constexpr int kClasses = 2;
  static const char* class_name(int c);
  void observe_class_wait(int work_class, double ms);

  struct Gauges {
    int queue_depth = 0;
    int inflight = 0;
    int connections_open = 0;
    std::uint64_t connections_total = 0;
    std::uint64_t frames = 0;
    std::uint64_t bytes_out = 0;
    std::uint64_t renders_dropped = 0;
    std::uint64_t renderer_rebuilds = 0;
    std::array<int, kClasses> class_queue_depth{};  // jobs with slices not yet taken
    std::uint64_t renders_cancelled = 0;  // stopped between slices: the client left
    std::uint64_t slices_dropped = 0;     // GPU batches not rendered for that reason
    std::uint64_t turns = 0;              // slices run in turns inside others
    // The render workers' scene-content caches (RenderService::scene_cache).
    std::uint64_t scene_cache_bytes = 0, scene_cache_budget_bytes = 0, scene_cache_entries = 0;
    std::uint64_t scene_cache_hits = 0, scene_cache_misses = 0, scene_cache_evictions = 0;
    std::map<std::string, std::uint64_t> errors;  // by code
    double uptime_s = 0;
  };
  // The whole exposition, gauges and counters the server keeps elsewhere included.
  std::string prometheus(const Gauges& g) const;

  static const char* stage_name(Stage s);

  struct Histogram {
    std::array<std::uint64_t, kBuckets.size() + 1> counts{};  // last: +Inf
    std::uint64_t count = 0;
    double sum_s = 0;
  };

 private:
  mutable std::mutex mu_;
  std::map<std::pair<std::string, bool>, std::uint64_t> requests_;
  std::array<Histogram, kStageCount> stages_{};
  std::array<Histogram, kClasses> class_waits_{};
  double gpu_s_ = 0;
};

struct ServerCore;
// Samples the gauges from the core's stats, render service and store.
Metrics::Gauges sample_gauges(const ServerCore& core);

// One structured log line per answered request on stderr (a JSON object:
// request id, method, outcome or error code, and the stage timings when there
// are any), unless config.request_log is off (--quiet-requests).
void log_request(const ServerCore& core, const nlohmann::json& id, const std::string& method,
                 const std::string& outcome, const nlohmann::json& timings = nullptr);

// GET /metrics (Prometheus text) and GET /health (the health JSON; 503 while
// draining) on the HTTP listener (server/http_server.hpp).
class HttpServer;
void register_metrics_routes(HttpServer& http, ServerCore& core);

// The health document: {"status": "ok"|"draining", ...}.
nlohmann::json health_json(bool shutting_down, const Metrics::Gauges& g, const std::string& renderer);

}  // namespace beamcast
