#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/frame_choice.hpp"
#include "cli/progress.hpp"
#include "cli/server_options.hpp"
#include "gi/gi_scene.hpp"
#include "gi/photon_gather.hpp"
#include "gi/photon_map.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/pass_plan.hpp"
#include "render/reference.hpp"
#include "render/renderer.hpp"

namespace beamcast::cli {
namespace {

struct RenderArgs {
  std::string scene;
  std::string out = ".";
  std::string assets;
  bool reference = false;
  bool json = false;
  bool hdr = false;
  int device = -1;
  std::string platform = "auto";
  int threads = 0;
  int spp = 64;
  std::uint64_t seed = 1;
  int bounces = 32;
  std::string gather;  // "", "radius" or "nearest": the CPU photon gather
  int gather_k = 50;
  FrameChoice choice;  // --camera, --size
  std::string prefix;  // before each file name
};

std::string frame_stem(const Camera& cam, std::size_t index) {
  return cam.name.empty() ? "camera_" + std::to_string(index) : cam.name;
}

// Writes the linear HDR buffer as raw little-endian float32 RGB (with a one-line
// JSON header file beside it) for analysis scripts.
void write_hdr(const std::filesystem::path& file, const HdrImage& hdr) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + file.string());
  std::fwrite(hdr.rgb.data(), sizeof(float), hdr.rgb.size(), f);
  std::fclose(f);
}

int run_render(const RenderArgs& args) {
  namespace fs = std::filesystem;
  SceneLoadOptions load;
  load.assets_dir = args.assets.empty() ? fs::path(args.scene).parent_path() : fs::path(args.assets);
  if (load.assets_dir.empty()) load.assets_dir = ".";
  Scene scene;
  try {
    scene = load_scene_file(args.scene, load);
    apply_frame_choice(args.choice, &scene.cameras);
  } catch (const ProtocolError& e) {
    std::fprintf(stderr, "beamcast: %s: [%s] %s%s%s\n", args.scene.c_str(), e.info().code.c_str(),
                 e.info().path.c_str(), e.info().path.empty() ? "" : ": ",
                 e.info().message.c_str());
    return 2;
  }
  fs::create_directories(args.out);

  nlohmann::json summary;
  summary["scene"] = args.scene;
  summary["method"] = args.reference ? "reference" : !args.gather.empty() ? "gather" : "gpu";
  summary["passes"] = plan_passes(scene);
  summary["frames"] = nlohmann::json::array();

  std::unique_ptr<Renderer> renderer;
  std::vector<FrameResult> frames;
  if (!args.gather.empty()) {
    // The CPU estimate from the same photon maps the GPU splats (gi/photon_gather):
    // "radius" is the splat pass's estimator in double, "nearest" the
    // textbook k-nearest one.
    if (!scene.has_gi()) {
      std::fprintf(stderr, "beamcast: --gather needs a scene with lights\n");
      return 2;
    }
    summary["renderer"] = "CPU photon gather (" + args.gather + ")";
    const GiScene surfaces(scene);
    const PhotonMaps maps = trace_photons(scene, surfaces, {.threads = args.threads});
    // Direct light as the GPU frame carries it: the direct pass's points with
    // exact visibility, or the photons straight from the lights.
    const PhotonGather gather(maps, scene.gi.direct == DirectLightMethod::kShadowMaps);
    summary["photons"] = {{"count", maps.global.size() + maps.caustic.size()},
                          {"trace_ms", maps.trace_ms}};
    GatherImageOptions gopts;
    gopts.method = args.gather == "nearest" ? GatherMethod::kNearest : GatherMethod::kFixedRadius;
    gopts.k = args.gather_k;
    gopts.threads = args.threads;
    for (const Camera& cam : scene.cameras) {
      const auto t0 = std::chrono::steady_clock::now();
      FrameResult fr;
      fr.hdr = gather_image(scene, surfaces, gather, cam, gopts);
      fr.image = tone_map(fr.hdr, scene.output);
      fr.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                       .count();
      if (!args.hdr) fr.hdr = {};
      frames.push_back(std::move(fr));
    }
  } else if (!args.reference) {
    RendererOptions ropts;
    ropts.egl.device_index = args.device;
    ropts.egl.platform = args.platform;
    renderer = std::make_unique<Renderer>(ropts);
    std::fprintf(stderr, "beamcast: renderer: %s\n", renderer->description().c_str());
    summary["renderer"] = renderer->description();
    frames = renderer->render(scene, FrameOptions{.read_hdr = args.hdr});
  } else {
    summary["renderer"] = "CPU reference (double precision)";
    ReferenceOptions refopts;
    refopts.threads = args.threads;
    refopts.gi_spp = args.spp;
    refopts.gi_seed = args.seed;
    refopts.gi_max_depth = args.bounces;
    if (scene.has_gi()) {
      summary["gi_spp"] = args.spp;
      summary["gi_bounces"] = args.bounces;
    }
    for (std::size_t i = 0; i < scene.cameras.size(); ++i) {
      const Camera& cam = scene.cameras[i];
      const auto t0 = std::chrono::steady_clock::now();
      // Progress in rows (a lit scene's twice: path tracing, then shading), on stderr.
      ProgressBar bar((scene.has_gi() ? 2 : 1) * cam.height,
                      frame_stem(cam, i) + ": CPU reference, rows", stderr, /*min_interval_s=*/1.0);
      std::mutex bar_mu;
      bar.update(0);
      refopts.on_progress = [&](int done, int) {
        std::lock_guard lock(bar_mu);
        bar.update(done);
      };
      FrameResult fr;
      fr.hdr = render_reference(scene, cam, refopts);
      bar.finish();
      fr.image = tone_map(fr.hdr, scene.output);
      fr.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                       .count();
      if (!args.hdr) fr.hdr = {};
      frames.push_back(std::move(fr));
    }
  }

  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Camera& cam = scene.cameras[i];
    const FrameResult& fr = frames[i];
    const fs::path file = fs::path(args.out) / (args.prefix + frame_stem(cam, i) + ".png");
    write_png(file, fr.image);
    nlohmann::json jf;
    jf["camera"] = frame_stem(cam, i);
    jf["file"] = file.string();
    jf["width"] = cam.width;
    jf["height"] = cam.height;
    jf["wall_ms"] = fr.wall_ms;
    if (!args.reference && args.gather.empty()) {
      jf["gpu_ms"] = fr.gpu_ms;
      jf["readback_ms"] = fr.readback_ms;
      for (const PassTiming& p : fr.passes) jf["passes"].push_back({{"name", p.name}, {"gpu_ms", p.gpu_ms}});
      if (fr.slim_points > 0) jf["slim_points"] = fr.slim_points;
      if (scene.has_gi()) {
        jf["photons"] = {{"count", fr.photons},
                         {"disks", fr.photon_disks},
                         {"trace_ms", fr.photon_trace_ms},
                         {"upload_ms", fr.photon_upload_ms}};
        if (fr.volume_photons > 0) jf["photons"]["volume"] = fr.volume_photons;
      }
    }
    if (args.hdr) {
      const fs::path raw = fs::path(args.out) / (args.prefix + frame_stem(cam, i) + ".rgb32f");
      write_hdr(raw, fr.hdr);
      jf["hdr_file"] = raw.string();
    }
    summary["frames"].push_back(jf);
    if (!args.json) {
      std::printf("%-24s %4dx%-4d wall %8.2f ms", file.filename().c_str(), cam.width, cam.height,
                  fr.wall_ms);
      if (!args.reference && args.gather.empty()) {
        std::printf("  gpu %7.3f ms (", fr.gpu_ms);
        for (std::size_t k = 0; k < fr.passes.size(); ++k) {
          std::printf("%s%s %.3f", k ? ", " : "", fr.passes[k].name.c_str(), fr.passes[k].gpu_ms);
        }
        std::printf(")  read-back %.2f ms", fr.readback_ms);
      }
      std::printf("\n");
    }
  }
  if (args.json) std::printf("%s\n", summary.dump(2).c_str());
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto remote = std::make_shared<RemoteRenderArgs>();
  auto seq = std::make_shared<SequenceArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a scene to one PNG per camera, offline or on a beamcast-server");
  CLI::Option* scene =
      cmd->add_option("scene", args->scene, "Scene JSON file (docs/scene-format.md)")
          ->check(CLI::ExistingFile);
  CLI::Option* out_opt = cmd->add_option(
      "--out,-o", args->out,
      "Output directory (created if missing); frames are named CAMERA.png (with --rig or "
      "--path: frame_0000.png ...). Without it: the current directory, with the scene's name "
      "before each file name (SCENE_CAMERA.png)");
  add_frame_choice_options(cmd, &args->choice);
  CLI::Option* assets =
      cmd->add_option("--assets", args->assets,
                      "Directory mesh files are read from (default: the scene file's directory)");
  CLI::Option* reference =
      cmd->add_flag("--reference", args->reference,
                    "Render with the double-precision CPU reference instead of the GPU");
  cmd->add_flag("--json", args->json, "Print a machine-readable summary on stdout");
  CLI::Option* hdr =
      cmd->add_flag("--hdr", args->hdr, "Also write the linear HDR buffer (.rgb32f, float32 RGB)");
  CLI::Option* device = cmd->add_option(
      "--device", args->device,
      "EGL device index (default: $BEAMCAST_EGL_DEVICE, else the first that works)");
  CLI::Option* platform =
      cmd->add_option("--platform", args->platform, "EGL platform: auto, device or surfaceless")
          ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  CLI::Option* threads =
      cmd->add_option("--threads", args->threads, "CPU reference threads (0: all cores)");
  CLI::Option* spp = cmd->add_option("--spp", args->spp,
                                     "CPU reference, scenes with lights: path-traced samples per pixel")
                         ->check(CLI::Range(1, 1 << 20));
  CLI::Option* seed = cmd->add_option("--seed", args->seed,
                                      "CPU reference, scenes with lights: the path tracer's seed");
  CLI::Option* bounces =
      cmd->add_option("--bounces", args->bounces,
                      "CPU reference, scenes with lights: surface interactions a path may have "
                      "(1: direct light only)")
          ->check(CLI::Range(1, 64))
          ->needs(reference);
  CLI::Option* gather =
      cmd->add_option("--gather", args->gather,
                      "Scenes with lights: the CPU photon gather on the same photons instead of "
                      "the GPU (radius: the splat estimator in double; nearest: k nearest)")
          ->check(CLI::IsMember({"radius", "nearest"}))
          ->excludes(reference);
  cmd->add_option("--gather-k", args->gather_k, "With --gather nearest: photons per estimate")
      ->check(CLI::Range(1, 100000))
      ->needs(gather);

  // Rendering on a server: the scene file is sent inline, or a stored scene named.
  CLI::Option* server =
      cmd->add_option("--server", remote->server,
                      "Render on the beamcast-server at HOST:PORT instead of locally (given "
                      "alone: $BEAMCAST_SERVER, else 127.0.0.1:7878); with --rig or --path, on "
                      "several (A,B,C): the batches are shared out and the frames written in order")
          ->expected(0, 1)
          ->default_str(default_server());
  cmd->add_option("--scene-id", remote->scene_id, "With --server: render this stored scene")
      ->needs(server)
      ->excludes(scene);
  cmd->add_option("--encoding", remote->encoding,
                  "With --server: PNG transport, binary (attachments) or base64")
      ->check(CLI::IsMember({"binary", "base64"}))
      ->needs(server);
  cmd->add_option("--frame-format", remote->frame_format,
                  "With --server: frames as png (the server encodes), or raw / raw_zstd "
                  "(samples, asked for in hello; PNG files written here)")
      ->check(CLI::IsMember({"png", "raw", "raw_zstd"}))
      ->capture_default_str()
      ->needs(server);
  cmd->add_option("--timeout", remote->timeout_s, "With --server: seconds to wait for the frames")
      ->check(CLI::PositiveNumber)
      ->needs(server);
  cmd->add_option("--token", remote->token,
                  "With --server: the token for hello, for servers started with one (default: "
                  "$BEAMCAST_TOKEN)")
      ->envname("BEAMCAST_TOKEN");
  // Frame sequences: numbered PNGs of a rig or a camera path.
  CLI::Option* rig = cmd->add_option(
      "--rig", seq->rig,
      "Render a rig framed by the scene's first camera instead of its cameras, to "
      "frame_0000.png ...: orbit:COUNT (around the beams' centre, starting at the first "
      "camera), cubemap[:SIZE], stereo[:SEPARATION]");
  CLI::Option* path = cmd->add_option("--path", seq->path,
                                      "Render a camera path (keyframes JSON, "
                                      "protocol/camera_path.hpp) to frame_0000.png ...")
                          ->check(CLI::ExistingFile)
                          ->excludes(rig);
  cmd->add_option("--frames", seq->frames, "With --path: frames to render (default: the file's)")
      ->check(CLI::Range(1, 100000))
      ->needs(path);
  CLI::Option* batch =
      cmd->add_option("--batch", seq->batch,
                      "With --rig or --path: views per render call or request (default 12)")
          ->check(CLI::Range(1, 256));
  CLI::Option* connections =
      cmd->add_option("--connections", seq->connections,
                      "With --server and --rig or --path: connections (workers) per server; "
                      "through a balancer, its servers share them")
          ->check(CLI::Range(1, 64))
          ->needs(server);
  for (CLI::Option* o : {rig, path}) {
    o->excludes(reference);
    o->excludes(gather);
  }
  // Options of the local renderer mean nothing to a server render.
  for (CLI::Option* local :
       {assets, reference, hdr, device, platform, threads, spp, seed, bounces, gather})
    server->excludes(local);

  cmd->callback([args, remote, seq, batch, connections, out_opt] {
    int rc = 0;
    // Without --out, frames go to the current directory named after the
    // scene as well as the camera, so renders of different scenes do not
    // overwrite each other.
    const std::string prefix =
        out_opt->count() > 0 ? std::string()
                             : (remote->scene_id.empty()
                                    ? std::filesystem::path(args->scene).stem().string()
                                    : remote->scene_id) + "_";
    if (!seq->rig.empty() || !seq->path.empty()) {
      if (args->scene.empty() && remote->scene_id.empty()) {
        throw CLI::ValidationError(
            "--rig and --path need a scene file, or --server with --scene-id (they frame the "
            "scene's first camera)");
      }
      seq->scene = args->scene;
      seq->scene_id = remote->scene_id;
      seq->prefix = prefix;
      seq->out = args->out;
      seq->assets = args->assets;
      seq->json = args->json;
      seq->device = args->device;
      seq->platform = args->platform;
      seq->server = remote->server;
      seq->encoding = remote->encoding;
      seq->timeout_s = remote->timeout_s;
      seq->token = remote->token;
      seq->choice = args->choice;
      rc = run_sequence(*seq);
    } else if (batch->count() > 0 || connections->count() > 0) {
      throw CLI::ValidationError("--batch and --connections apply to --rig and --path only");
    } else if (!remote->server.empty()) {
      if (args->scene.empty() && remote->scene_id.empty()) {
        throw CLI::ValidationError("render --server needs a scene file or --scene-id");
      }
      remote->scene = args->scene;
      remote->out = args->out;
      remote->json = args->json;
      remote->choice = args->choice;
      remote->prefix = prefix;
      rc = run_remote_render(*remote);
    } else {
      if (args->scene.empty()) throw CLI::RequiredError("scene");
      args->prefix = prefix;
      rc = run_render(*args);
    }
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

void add_info_command(CLI::App& app) {
  auto egl = std::make_shared<EglOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Create the headless GL context and report it");
  cmd->add_option("--device", egl->device_index, "EGL device index");
  cmd->add_option("--platform", egl->platform, "EGL platform: auto, device or surfaceless")
      ->check(CLI::IsMember({"auto", "device", "surfaceless"}));
  cmd->callback([egl] {
    RendererOptions opts;
    opts.egl = *egl;
    Renderer renderer(opts);
    std::printf("%s\n", renderer.description().c_str());
  });
}

}  // namespace beamcast::cli
