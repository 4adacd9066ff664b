// `beamcast bench accuracy`: the accuracy/time benchmark of bench/accuracy.hpp;
// `bench views`; `bench slim` (bench/slim_bench.hpp); `bench gi` (bench/gi_bench.py, run with this binary);
// `bench medium` (bench/medium_bench.py, likewise), `bench medium-rule`, `bench fog`
// (bench/fog_bench.py), `bench povray` (bench/povray_bench.py) and `bench volumes`
// (bench/volume_bench.hpp).
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "bench/accuracy_report.hpp"
#include "protocol/data_dir.hpp"

#include "bench/accuracy.hpp"
#include "bench/slim_bench.hpp"
#include "bench/volume_bench.hpp"
#include "bench/views.hpp"
#include "protocol/density.hpp"
#include "render/beam_medium.hpp"
#include "cli/commands.hpp"

namespace beamcast::cli {

namespace {

// Runs bench/SCRIPT with bench::python_interpreter(), this binary and --out OUT, plus
// `extra` (already quoted); a failing script fails the command.
void run_python_bench(const std::string& script_name, const std::string& out,
                      const std::string& extra) {
  const std::filesystem::path script = find_data_dir("bench") / script_name;
  const std::string cmd =
      bench::shell_quote(bench::python_interpreter()) + " " + bench::shell_quote(script.string()) +
      " --binary " +
      bench::shell_quote(std::filesystem::read_symlink("/proc/self/exe").string()) + " --out " +
      bench::shell_quote(out) + extra;
  const int status = std::system(cmd.c_str());
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw CLI::RuntimeError(status == -1 || !WIFEXITED(status) ? 1 : WEXITSTATUS(status));
  }
}

// A subcommand NAME that runs bench/SCRIPT with --out and optional --size
// and --spp (their defaults, stated in the help, are the script's).
void add_size_spp_bench(CLI::App* bench, const char* name, const std::string& help,
                        const std::string& script, int default_size, int default_spp) {
  struct Args {
    std::string out;
    int size = 0, spp = 0;
  };
  auto opts = std::make_shared<Args>();
  CLI::App* cmd = bench->add_subcommand(name, help);
  cmd->add_option("--out,-o", opts->out, "Output directory (created if missing)")->required();
  cmd->add_option("--size", opts->size,
                  "Frame width and height (default " + std::to_string(default_size) + ")")
      ->check(CLI::Range(16, 4096));
  cmd->add_option("--spp", opts->spp,
                  "Reference paths per pixel per seed (default " + std::to_string(default_spp) +
                      ")")
      ->check(CLI::Range(1, 1 << 20));
  cmd->callback([opts, script] {
    std::string extra;
    if (opts->size > 0) extra += " --size " + std::to_string(opts->size);
    if (opts->spp > 0) extra += " --spp " + std::to_string(opts->spp);
    run_python_bench(script, opts->out, extra);
  });
}

}  // namespace

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
  acc->add_flag_function(
      "--no-plots", [opts](std::int64_t) { opts->plots = false; }, "Do not run bench/plot_accuracy.py");
  acc->add_option("--device", opts->egl.device_index,
                  "EGL device index (default: $BEAMCAST_EGL_DEVICE, else the first that works)");
  acc->add_option("--platform", opts->egl.platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  acc->callback([opts] {
    const int rc = bench::run_accuracy(*opts);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  auto volopts = std::make_shared<bench::VolumeBenchOptions>();
  CLI::App* volumes = bench->add_subcommand(
      "volumes",
      "Volume ray casting against the CPU reference: samples per voxel along and across the "
      "ray (S_z, S_xy) and the resolution level (R_v), each with error columns, ERT and empty-space skipping on a sparse and a dense volume; writes "
      "volumes.csv and volumes.md to --out");
  volumes->add_option("--out,-o", volopts->out, "Output directory (created if missing)")->required();
  volumes->add_flag("--quick", volopts->quick, "96x96, small volumes, fewer settings");
  volumes->add_option("--size", volopts->size, "Frame width and height (default 512, 96 with --quick)")
      ->check(CLI::Range(16, 4096));
  volumes->add_option("--repeats", volopts->repeats, "GPU frames per row, median reported (default 3)")
      ->check(CLI::Range(1, 100));
  volumes->add_option("--reference-spv", volopts->reference_spv,
                      "The reference's samples per voxel spacing (default 8)")
      ->check(CLI::Range(1.0, 256.0));
  volumes->add_option("--skull", volopts->skull,
                      "skull_2.9.inr (scripts/fetch_cgal_volumes.sh): the sparse volume of the ERT "
                      "and skipping rows")
      ->check(CLI::ExistingFile);
  volumes->add_flag("--images", volopts->images, "Each row's frame as a PNG");
  volumes->add_option("--device", volopts->egl.device_index, "EGL device index");
  volumes->add_option("--platform", volopts->egl.platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  volumes->callback([volopts] { bench::run_volume_bench(*volopts); });

  auto sopts = std::make_shared<bench::SlimBenchOptions>();
  CLI::App* slim = bench->add_subcommand(
      "slim",
      "SLIM point sampling against the CPU reference: sampling S, depth threshold, the second "
      "stage, zoom 0.25x-16x, per model; writes slim.csv and slim.md to --out");
  slim->add_option("--out,-o", sopts->out, "Output directory (created if missing)")->required();
  slim->add_flag("--quick", sopts->quick, "128x128, fewer settings (about a minute on 2 cores)");
  slim->add_option("--size", sopts->size, "Frame width and height (default 512, 128 with --quick)")
      ->check(CLI::Range(16, 4096));
  slim->add_option("--repeats", sopts->repeats, "GPU frames per row, median reported (default 3)")
      ->check(CLI::Range(1, 100));
  slim->add_option(
          "--reference-samples", sopts->reference_samples,
          "Reference depth and normal averaged over K x K rays per pixel (default 1: the centre)")
      ->check(CLI::Range(1, 8));
  slim->add_option("--zoom", sopts->zooms,
                   "Only these zooms (repeatable; default 0.25 1 4 16, --quick 0.25 1 4)")
      ->check(CLI::Range(0.01, 1000.0));
  slim->add_flag("--zoom-only", sopts->zoom_only, "Only the zoom rows (not the S and t rows)");
  slim->add_flag("--no-generated", sopts->no_generated,
                 "Only the --model files (not the generated sphere and torus)");
  slim->add_option("--evaluation", sopts->evaluations,
                   "Only the rows of this slim.evaluation (repeatable: field, patch, blend)")
      ->check(CLI::IsMember({"field", "patch", "blend"}));
  slim->add_flag("--images", sopts->images,
                 "Coverage pictures of the zoom rows (grey: both, red: holes, blue: spurious)");
  slim->add_option("--model", sopts->models,
                   "A SLIM model file (JSON or binary, e.g. from `beamcast slim fit`; repeatable)")
      ->check(CLI::ExistingFile);
  slim->add_option("--mesh", sopts->meshes,
                   "The mesh the i-th --model was fitted to (OFF, OBJ or PLY; repeatable): rasterized "
                   "at the same cameras for time and image difference")
      ->check(CLI::ExistingFile);
  slim->add_option("--device", sopts->egl.device_index, "EGL device index");
  slim->add_option("--platform", sopts->egl.platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  slim->callback([sopts] {
    const int rc = bench::run_slim_bench(*sopts);
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
  views->add_flag_function(
      "--no-renderer", [vopts](std::int64_t) { vopts->renderer = false; },
      "Skip the in-process renderer timings (batched vs one camera at a time)");
  views->add_flag_function(
      "--no-plots", [vopts](std::int64_t) { vopts->plots = false; }, "Do not run bench/plot_views.py");
  views->callback([vopts] {
    const int rc = bench::run_views(*vopts);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });

  // Photon-mapped GI against the path tracer: bench/gi_bench.py drives this
  // binary's `render` (GPU, --reference, --gather) and compares the images
  // with numpy; the subcommand runs it with this binary.
  struct GiArgs {
    std::string out, scene;
    bool quick = false;
    int size = 0, spp = 0;
    std::vector<std::string> references;  // --reference-hdr PATH:SPP
  };
  auto gopts = std::make_shared<GiArgs>();
  CLI::App* gi = bench->add_subcommand(
      "gi",
      "Photon splatting against the path-traced reference on the Cornell box: photon count, "
      "kernel and radius, error per wall against time; writes gi.csv, gi.md and gi.png to --out "
      "(runs bench/gi_bench.py with /usr/bin/python3 and numpy)");
  gi->add_option("--out,-o", gopts->out, "Output directory (created if missing)")->required();
  gi->add_flag("--quick", gopts->quick, "128x128, reference 64 spp, up to 1e5 photons (seconds)");
  gi->add_option("--size", gopts->size, "Frame width and height (default 512, 128 with --quick)")
      ->check(CLI::Range(16, 4096));
  gi->add_option("--spp", gopts->spp, "Reference samples per pixel (default 1024, 64 with --quick)")
      ->check(CLI::Range(1, 1 << 20));
  gi->add_option("--scene", gopts->scene, "Scene (default examples/cornell_box.json)");
  gi->add_option("--reference-hdr", gopts->references,
                 "PATH:SPP of a path-traced render (.rgb32f) of the scene to use as the reference "
                 "instead of rendering one; at least two, independent");
  gi->callback([gopts] {
    std::string extra;
    if (gopts->quick) extra += " --quick";
    if (gopts->size > 0) extra += " --size " + std::to_string(gopts->size);
    if (gopts->spp > 0) extra += " --spp " + std::to_string(gopts->spp);
    if (!gopts->scene.empty()) extra += " --scene " + bench::shell_quote(gopts->scene);
    for (const std::string& r : gopts->references) {
      extra += " --reference-hdr " + bench::shell_quote(r);
    }
    run_python_bench("gi_bench.py", gopts->out, extra);
  });

  // Beams through a medium on the GPU against the reference, per rule and
  // step across sigma_t r: bench/medium_bench.py with this binary.
  struct MediumArgs {
    std::string out;
    int size = 0;
  };
  auto mopts = std::make_shared<MediumArgs>();
  CLI::App* medium = bench->add_subcommand(
      "medium",
      "Beams seen through a homogeneous medium against the CPU reference: the beam rule and step "
      "across sigma_t r, image error and GPU time; writes medium.csv, medium.md and medium.png to "
      "--out (runs bench/medium_bench.py with /usr/bin/python3 and numpy)");
  medium->add_option("--out,-o", mopts->out, "Output directory (created if missing)")->required();
  medium->add_option("--size", mopts->size, "Frame width and height (default 256)")
      ->check(CLI::Range(16, 4096));
  medium->callback([mopts] {
    run_python_bench("medium_bench.py", mopts->out,
                     mopts->size > 0 ? " --size " + std::to_string(mopts->size) : "");
  });

  // Light scattered in fog: the seed's volume estimate against the beam
  // radiance estimate and the path tracer, LOD and the seed's segments
  // (bench/fog_bench.py).
  add_size_spp_bench(
      bench, "fog",
      "In-scattered light in fog on examples/fog_stage.json, a denser copy and "
      "examples/ground_fog.json (its layer also as a mesh region): the volume photon estimate and "
      "the beam radiance estimate against the path tracer, photon count, LOD, the number of "
      "view-ray segments, GPU time; writes fog.csv, fog.md, fog.png and fog_segments.png to --out (runs "
      "bench/fog_bench.py with /usr/bin/python3 and numpy)",
      "fog_bench.py", 256, 2048);
  // The Cornell box beside POV-Ray 3.7 (issue 14's peer; installed by the
  // script, not by the tests): time and error against one reference.
  add_size_spp_bench(
      bench, "povray",
      "The Cornell box beside POV-Ray 3.7 (radiosity presets; installs the povray package if "
      "missing) and the path tracer: time and error against one path-traced reference, time to "
      "equal error; writes povray.csv, povray.md, povray.png to --out (runs "
      "bench/povray_bench.py with /usr/bin/python3 and numpy)",
      "povray_bench.py", 512, 1024);

  // The beam rule's own error in double (render/beam_medium.hpp), as CSV on
  // stdout: what medium_bench.py plots beside the GPU's image error.
  CLI::App* rule = bench->add_subcommand(
      "medium-rule",
      "The beam-in-medium rule's own error in double (exact moments) per density, sigma_t r and "
      "variant, against the exact integral; CSV on stdout");
  rule->callback([] {
    std::printf("density,sigma_r,rule,step,worst_rel_error\n");
    for (std::string_view view : density_names()) {
      const std::string name(view);
      Density f;
      if (!density_from_name(name, &f)) continue;
      for (double kappa : {1e-3, 1e-2, 0.1, 0.3, 1.0, 3.0, 10.0}) {
        for (const auto& [r, step] : {std::pair{BeamMediumRule::kGauss2, 2.0},
                                      std::pair{BeamMediumRule::kGauss2, 1.0},
                                      std::pair{BeamMediumRule::kGauss2, 0.5},
                                      std::pair{BeamMediumRule::kMidpoint, 1.0},
                                      std::pair{BeamMediumRule::kMidpoint, 8.0}}) {
          std::printf("%s,%g,%s,%g,%.3e\n", name.c_str(), kappa,
                      r == BeamMediumRule::kGauss2 ? "gauss2" : "midpoint", step,
                      beam_rule_worst_error(f, kappa, r, step));
        }
      }
    }
  });
}

}  // namespace beamcast::cli
