// `beamcast load`: the command's options; the load generator itself, its
// report and its checks are bench/load_generator.cpp.
#include <memory>
#include <stdexcept>

#include "bench/load_generator.hpp"
#include "cli/commands.hpp"
#include "client/client.hpp"

namespace beamcast::cli {

void add_load_command(CLI::App& app) {
  auto args = std::make_shared<bench::LoadArgs>();
  CLI::App* cmd = app.add_subcommand(
      "load", "Load-test a beamcast-server: N connections, closed or open loop; latency "
              "percentiles, throughput, errors; every frame verified");
  cmd->add_option("--server", args->server, "HOST:PORT of beamcast-server")->required();
  cmd->add_option("--connections,-c", args->connections, "Connections")
      ->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--duration", args->duration_s, "Seconds of load (ignored with --requests)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--requests", args->requests, "Total requests instead of a duration")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rate", args->rate,
                  "Open loop: requests/s over all connections (0: closed loop)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--size", args->size, "Frame width and height")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--scene", args->scene_file, "Scene file (stored once on the server)")
      ->capture_default_str();
  cmd->add_option("--poses", args->poses, "Camera poses: fixed, orbit, random or mix")
      ->check(CLI::IsMember({"fixed", "orbit", "random", "mix"}))->capture_default_str();
  cmd->add_option("--cameras", args->cameras, "Cameras per request (0: 1, and 4 every 4th request)")
      ->check(CLI::Range(0, 64))->capture_default_str();
  cmd->add_option("--verify-fraction", args->verify_fraction,
                  "Fraction of requests whose frames are compared with a local render")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  cmd->add_option("--tolerance", args->tolerance,
                  "Largest per-channel difference (8-bit levels) from the local render")
      ->capture_default_str();
  cmd->add_option("--inflight", args->inflight_per_connection,
                  "Open loop: requests in flight per connection before one is skipped")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--pipeline", args->pipeline,
                  "Closed loop: requests each connection keeps in flight (fairness: -c 4 "
                  "--pipeline 16 --cameras 1)")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--preview-connections", args->preview_connections,
                  "Mix: preview-like closed-loop connections (one camera moving along an "
                  "orbit, quality auto)")
      ->check(CLI::Range(0, 1000))->capture_default_str();
  cmd->add_option("--preview-size", args->preview_size, "Mix: preview frame width and height")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--preview-budget", args->preview_budget_ms, "Mix: preview budget_ms")
      ->check(CLI::Range(1.0, 10000.0))->capture_default_str();
  cmd->add_option("--preview-step", args->preview_step_deg,
                  "Mix: degrees the preview camera moves along its orbit per frame")
      ->check(CLI::Range(0.001, 180.0))->capture_default_str();
  cmd->add_option("--batch-connections", args->batch_connections,
                  "Mix: batch-like connections (multi-camera orbit renders, quality full)")
      ->check(CLI::Range(0, 1000))->capture_default_str();
  cmd->add_option("--batch-cameras", args->batch_cameras, "Mix: cameras per batch request")
      ->check(CLI::Range(1, 64))->capture_default_str();
  cmd->add_option("--batch-size", args->batch_size, "Mix: batch frame width and height")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--batch-rate", args->batch_rate,
                  "Mix: batch requests/s over the batch connections (0: closed loop)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--batch-pipeline", args->batch_pipeline,
                  "Mix, closed loop: batch requests each batch connection keeps in flight")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--busy-backoff", args->busy_backoff_ms,
                  "Closed loop: milliseconds a connection waits after a busy answer")
      ->capture_default_str();
  cmd->add_option("--timeout", args->timeout_s, "Seconds to wait for outstanding answers at the end")
      ->capture_default_str();
  cmd->add_option("--token", args->token, "Token for hello (servers on non-loopback addresses)")
      ->envname("BEAMCAST_TOKEN");
  cmd->add_option("--frame-format", args->frame_format,
                  "Frames as png, or raw / raw_zstd samples (asked for in hello); every frame is "
                  "decoded either way")
      ->check(CLI::IsMember({"png", "raw", "raw_zstd"}))
      ->capture_default_str();
  cmd->add_option("--attempts", args->max_attempts,
                  "Tries of a connection that drops or is refused before its requests fail "
                  "(reconnects with backoff and jitter; 1: no retries)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--timeline-ms", args->timeline_ms, "Width of the timeline's buckets in the report")
      ->check(CLI::Range(10.0, 3.6e6));
  cmd->add_flag("--json", args->json_out, "Print the results as JSON");
  cmd->add_flag("--quiet,-q", args->quiet, "No live progress line");
  cmd->callback([args] {
    try {
      (void)client::parse_endpoint(args->server);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--server", e.what());
    }
    const int rc = bench::run_load(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace beamcast::cli
