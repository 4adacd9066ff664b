// `beamcast bench accuracy`: the accuracy/time benchmark of bench/accuracy.hpp.
#include <memory>

#include "bench/accuracy.hpp"
#include "bench/views.hpp"
#include "cli/commands.hpp"

namespace beamcast::cli {

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks of the local renderer");
  bench->require_subcommand(1);

  auto opts = std::make_shared<bench::AccuracyOptions>();
  CLI::App* acc = bench->add_subcommand(
      "accuracy",
      "Error against the CPU reference versus GPU time for every integration setting; writes "
      "accuracy.csv, accuracy.md and plots to --out");
  acc->add_option("--out,-o", opts->out, "Output directory (created if missing)")->required();
  acc->add_flag("--quick", opts->quick,
                "3 scenes at 128x128, a coarse grid, 3 repeats (under a minute on 2 cores)");
  acc->add_option("--size", opts->size, "Frame width and height (default 512, 128 with --quick)")
      ->check(CLI::Range(16, 4096));
  acc->add_option("--scene", opts->scenes, "Only this scene (repeatable); names as in the CSV");
  acc->add_flag("!--no-plots", opts->plots, "Do not run bench/plot_accuracy.py");
  acc->add_option("--device", opts->egl.device_index,
                  "EGL device index (default: $BEAMCAST_EGL_DEVICE, else the first that works)");
  acc->add_option("--platform", opts->egl.platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  acc->callback([opts] {
    const int rc = bench::run_accuracy(*opts);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  auto vopts = std::make_shared<bench::ViewsOptions>();
  CLI::App* views = bench->add_subcommand(
      "views",
      "K views of the 10-set scene: one K-camera request versus K pipelined requests, end to "
      "end through a server, and the renderer batched versus one camera at a time; writes "
      "views.csv, views.md and views.png to --out");
  views->add_option("--out,-o", vopts->out, "Output directory (created if missing)")->required();
  views->add_flag("--quick", vopts->quick, "K = 1, 2, 4 at 128x128, one round (seconds)");
  views->add_option("--views,-k", vopts->views, "View counts K (repeatable; default 1 2 4 8 16 36)")
      ->check(CLI::Range(1, 64));
  views->add_option("--size", vopts->size, "Frame width and height (default 512, 128 with --quick)")
      ->check(CLI::Range(16, 4096));
  views->add_option("--rounds", vopts->rounds, "Interleaved rounds (default 3, 1 with --quick)")
      ->check(CLI::Range(1, 100));
  views->add_option("--server", vopts->server,
                    "Use the beamcast-server at HOST:PORT (default: start one as a child)");
  views->add_option("--server-binary", vopts->server_binary,
                    "beamcast-server to start (default: the one beside this program)");
  views->add_flag("!--no-renderer", vopts->renderer,
                  "Skip the in-process renderer timings (batched vs one camera at a time)");
  views->add_flag("!--no-plots", vopts->plots, "Do not run bench/plot_views.py");
  views->callback([vopts] {
    const int rc = bench::run_views(*vopts);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace beamcast::cli
