#include "server/metrics.hpp"

#include <cstdio>

namespace beamcast {
namespace {

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Label values are server-chosen, but escape per the format anyway.
std::string label(const std::string& v) {
  std::string out;
  for (char c : v) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

void header(std::string& o, const char* name, const char* type, const char* help) {
  o += "# HELP ";
  o += name;
  o += ' ';
  o += help;
  o += "\n# TYPE ";
  o += name;
  o += ' ';
  o += type;
  o += '\n';
}

// A metric of one unlabelled sample: its HELP and TYPE lines, then the value.
void scalar(std::string& o, const char* name, const char* type, const char* help,
            const std::string& value) {
  header(o, name, type, help);
  o += name;
  o += ' ';
  o += value;
  o += '\n';
}

}  // namespace

const char* Metrics::stage_name(Stage s) {
  switch (s) {
    case kQueue: return "queue";
    case kRender: return "render";
    case kEncode: return "encode";
    case kTotal: return "total";
    default: return "?";
  }
}

const char* Metrics::class_name(int c) { return c == 0 ? "interactive" : "batch"; }

namespace {

void add_to(Metrics::Histogram& h, double ms) {
  const double s = ms / 1000.0;
  std::size_t i = 0;
  while (i < Metrics::kBuckets.size() && s > Metrics::kBuckets[i]) ++i;
  ++h.counts[i];
  ++h.count;
  h.sum_s += s;
}

// The bucket, sum and count lines of one histogram; `labels` without braces.
void write_histogram(std::string& o, const char* name, const std::string& labels,
                     const Metrics::Histogram& h) {
  std::uint64_t cum = 0;
  for (std::size_t i = 0; i < Metrics::kBuckets.size(); ++i) {
    cum += h.counts[i];
    char le[32];
    std::snprintf(le, sizeof le, "%g", Metrics::kBuckets[i]);  // bucket bounds as written: "0.05"
    o += std::string(name) + "_bucket{" + labels + ",le=\"" + le + "\"} " + std::to_string(cum) + "\n";
  }
  cum += h.counts.back();
  o += std::string(name) + "_bucket{" + labels + ",le=\"+Inf\"} " + std::to_string(cum) + "\n";
  o += std::string(name) + "_sum{" + labels + "} " + num(h.sum_s) + "\n";
  o += std::string(name) + "_count{" + labels + "} " + std::to_string(h.count) + "\n";
}

}  // namespace

void Metrics::observe_class_wait(int work_class, double ms) {
  if (work_class < 0 || work_class >= kClasses) return;
  std::lock_guard lock(mu_);
  add_to(class_waits_[static_cast<std::size_t>(work_class)], ms);
}

void Metrics::count_request(const std::string& method, bool ok) {
  std::lock_guard lock(mu_);
  ++requests_[{method, ok}];
}

void Metrics::observe(Stage stage, double ms) {
  std::lock_guard lock(mu_);
  add_to(stages_[stage], ms);
}

void Metrics::add_gpu_ms(double ms) {
  std::lock_guard lock(mu_);
  gpu_s_ += ms / 1000.0;
}

std::string Metrics::prometheus(const Gauges& g) const {
  std::string o;
  std::lock_guard lock(mu_);
  header(o, "beamcast_requests_total", "counter", "Requests answered, by method and outcome.");
  for (const auto& [key, n] : requests_) {
    o += "beamcast_requests_total{method=\"" + label(key.first) + "\",outcome=\"" +
         (key.second ? "ok" : "error") + "\"} " + std::to_string(n) + "\n";
  }
  header(o, "beamcast_errors_total", "counter", "Error responses and connection faults, by code.");
  for (const auto& [code, n] : g.errors) {
    o += "beamcast_errors_total{code=\"" + label(code) + "\"} " + std::to_string(n) + "\n";
  }
  header(o, "beamcast_stage_seconds", "histogram",
         "Render request latency by stage: queue wait, render (GPU + readback), PNG encode, "
         "and total time in the server.");
  for (int s = 0; s < kStageCount; ++s) {
    write_histogram(o, "beamcast_stage_seconds",
                    std::string("stage=\"") + stage_name(static_cast<Stage>(s)) + "\"", stages_[s]);
  }
  header(o, "beamcast_class_wait_seconds", "histogram",
         "Render queue wait by scheduling class (interactive: quality auto; batch: the rest), "
         "from arrival until the first slice reached a render worker.");
  for (int c = 0; c < kClasses; ++c) {
    write_histogram(o, "beamcast_class_wait_seconds",
                    std::string("class=\"") + class_name(c) + "\"", class_waits_[c]);
  }
  header(o, "beamcast_class_queue_depth", "gauge",
         "Render jobs with slices waiting for a GL worker, by scheduling class.");
  for (int c = 0; c < kClasses; ++c) {
    o += std::string("beamcast_class_queue_depth{class=\"") + class_name(c) + "\"} " +
         std::to_string(g.class_queue_depth[c]) + "\n";
  }
  scalar(o, "beamcast_renders_cancelled_total", "counter",
         "Renders stopped between slices because their client left.", std::to_string(g.renders_cancelled));
  scalar(o, "beamcast_slices_dropped_total", "counter",
         "Render slices (GPU batches) not rendered because their client left.", std::to_string(g.slices_dropped));
  scalar(o, "beamcast_render_turns_total", "counter",
         "Cheap slices rendered in turns inside long ones.", std::to_string(g.turns));
  scalar(o, "beamcast_gpu_seconds_total", "counter", "GPU time of rendered frames (timer queries).", num(gpu_s_));
  scalar(o, "beamcast_frames_total", "counter", "Frames sent.", std::to_string(g.frames));
  scalar(o, "beamcast_bytes_out_total", "counter", "Bytes of response frames queued for sending.", std::to_string(g.bytes_out));
  scalar(o, "beamcast_renders_dropped_total", "counter", "Queued renders dropped because their client left.", std::to_string(g.renders_dropped));
  scalar(o, "beamcast_renderer_rebuilds_total", "counter",
         "Render contexts discarded and recreated after a GL error.", std::to_string(g.renderer_rebuilds));
  scalar(o, "beamcast_scene_cache_bytes", "gauge",
         "Uploads of scene content (occluder triangles, SLIM spheres) kept across renders.", std::to_string(g.scene_cache_bytes));
  scalar(o, "beamcast_scene_cache_budget_bytes", "gauge",
         "The scene-content caches' budget, summed over render workers.", std::to_string(g.scene_cache_budget_bytes));
  scalar(o, "beamcast_scene_cache_entries", "gauge", "Entries in the scene-content caches.", std::to_string(g.scene_cache_entries));
  scalar(o, "beamcast_scene_cache_hits_total", "counter", "Renders that found their upload cached.", std::to_string(g.scene_cache_hits));
  scalar(o, "beamcast_scene_cache_misses_total", "counter", "Renders that made their upload.", std::to_string(g.scene_cache_misses));
  scalar(o, "beamcast_scene_cache_evictions_total", "counter",
         "Scene-content cache entries evicted (least recently used) for the budget.", std::to_string(g.scene_cache_evictions));
  scalar(o, "beamcast_queue_depth", "gauge", "Render jobs waiting for a GL worker.", std::to_string(g.queue_depth));
  scalar(o, "beamcast_inflight", "gauge", "Render jobs admitted and not yet answered.", std::to_string(g.inflight));
  scalar(o, "beamcast_connections_open", "gauge", "Open client connections.", std::to_string(g.connections_open));
  scalar(o, "beamcast_connections_total", "counter", "Connections accepted.", std::to_string(g.connections_total));
  scalar(o, "beamcast_uptime_seconds", "gauge", "Seconds since the server started.", num(g.uptime_s));
  return o;
}

nlohmann::json health_json(bool shutting_down, const Metrics::Gauges& g, const std::string& renderer) {
  return {{"status", shutting_down ? "draining" : "ok"},
          {"renderer", renderer},
          {"uptime_s", g.uptime_s},
          {"queue_depth", g.queue_depth},
          {"inflight", g.inflight},
          {"connections_open", g.connections_open}};
}

}  // namespace beamcast
