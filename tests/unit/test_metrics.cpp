// Prometheus text rendering of server/metrics (no sockets, no GL).
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "server/metrics.hpp"

namespace beamcast {
namespace {

// The value on the line that starts with `series` (exact match up to the space).
double value_of(const std::string& text, const std::string& series) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(series + " ", 0) == 0) return std::stod(line.substr(series.size() + 1));
  }
  ADD_FAILURE() << "no series " << series << " in\n" << text;
  return -1;
}

TEST(ServerMetrics, CountersHistogramsAndGaugesRender) {
  Metrics m;
  m.count_request("render", true);
  m.count_request("render", true);
  m.count_request("render", false);
  m.count_request("ping", true);
  m.observe(Metrics::kRender, 0.5);    // 0.0005 s: first bucket (le 0.001)
  m.observe(Metrics::kRender, 30.0);   // 0.03 s: le 0.05
  m.observe(Metrics::kRender, 90000);  // 90 s: only +Inf
  m.add_gpu_ms(250);
  Metrics::Gauges g;
  g.queue_depth = 3;
  g.frames = 7;
  g.errors = {{"busy", 4}};
  const std::string t = m.prometheus(g);
  EXPECT_EQ(value_of(t, R"(beamcast_requests_total{method="render",outcome="ok"})"), 2);
  EXPECT_EQ(value_of(t, R"(beamcast_requests_total{method="render",outcome="error"})"), 1);
  EXPECT_EQ(value_of(t, R"(beamcast_requests_total{method="ping",outcome="ok"})"), 1);
  EXPECT_EQ(value_of(t, R"(beamcast_errors_total{code="busy"})"), 4);
  // Buckets are cumulative.
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_bucket{stage="render",le="0.001"})"), 1);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_bucket{stage="render",le="0.025"})"), 1);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_bucket{stage="render",le="0.05"})"), 2);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_bucket{stage="render",le="30"})"), 2);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_bucket{stage="render",le="+Inf"})"), 3);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_count{stage="render"})"), 3);
  EXPECT_NEAR(value_of(t, R"(beamcast_stage_seconds_sum{stage="render"})"), 90.0305, 1e-9);
  EXPECT_EQ(value_of(t, R"(beamcast_stage_seconds_count{stage="queue"})"), 0);
  EXPECT_DOUBLE_EQ(value_of(t, "beamcast_gpu_seconds_total"), 0.25);
  EXPECT_EQ(value_of(t, "beamcast_queue_depth"), 3);
  EXPECT_EQ(value_of(t, "beamcast_frames_total"), 7);
  // Every family has HELP and TYPE, and the text ends with a newline.
  EXPECT_NE(t.find("# TYPE beamcast_stage_seconds histogram\n"), std::string::npos);
  EXPECT_NE(t.find("# TYPE beamcast_requests_total counter\n"), std::string::npos);
  EXPECT_EQ(t.back(), '\n');
}

TEST(ServerMetrics, HealthDocument) {
  Metrics::Gauges g;
  g.inflight = 2;
  EXPECT_EQ(health_json(false, g, "llvmpipe")["status"], "ok");
  EXPECT_EQ(health_json(true, g, "llvmpipe")["status"], "draining");
  EXPECT_EQ(health_json(false, g, "llvmpipe")["inflight"], 2);
}

}  // namespace
}  // namespace beamcast
