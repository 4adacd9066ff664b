// `beamcast render --rig SPEC | --path FILE`: a turntable, cube map, stereo
// pair or keyframed animation rendered to numbered PNGs (frame_0000.png ...),
// locally or on a server, in batches of views, with progress on stderr and a
// per-frame time summary.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "client/client.hpp"
#include "protocol/camera_path.hpp"
#include "protocol/rigs.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "render/renderer.hpp"

namespace beamcast::cli {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

void print_error(const std::string& where, const ErrorInfo& e) {
  std::fprintf(stderr, "beamcast: %s: [%s] %s%s%s\n", where.c_str(), e.code.c_str(),
               e.path.c_str(), e.path.empty() ? "" : ": ", e.message.c_str());
}

fs::path frame_file(const fs::path& dir, std::size_t i) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04zu.png", i);
  return dir / name;
}

void write_bytes(const fs::path& file, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(file, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error("cannot write " + file.string());
}

// The cameras of the job: the rig or the path, framed by the scene.
std::vector<Camera> sequence_cameras(const SequenceArgs& args, const Scene& scene) {
  if (!args.rig.empty()) return rig_from_spec(args.rig, scene);
  std::ifstream in(args.path);
  if (!in) {
    throw ProtocolError(ErrorInfo{"file_not_found", "cannot read " + args.path, ""});
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw ProtocolError(ErrorInfo{"bad_json", e.what(), ""});
  }
  const CameraPath path = parse_camera_path(j, scene.cameras.front(), SceneLimits{});
  return expand_camera_path(path, args.frames);
}

}  // namespace

int run_sequence(const SequenceArgs& args) {
  SceneLoadOptions load;
  load.assets_dir = args.assets.empty() ? fs::path(args.scene).parent_path() : fs::path(args.assets);
  if (load.assets_dir.empty()) load.assets_dir = ".";
  Scene scene;
  std::vector<Camera> cams;
  try {
    scene = load_scene_file(args.scene, load);
  } catch (const ProtocolError& e) {
    print_error(args.scene, e.info());
    return 2;
  }
  try {
    cams = sequence_cameras(args, scene);
  } catch (const ProtocolError& e) {
    print_error(args.rig.empty() ? args.path : "--rig", e.info());
    return 2;
  }
  fs::create_directories(args.out);
  const std::size_t n = cams.size();
  const std::size_t batch = static_cast<std::size_t>(std::max(1, args.batch));
  std::vector<double> frame_ms(n, 0.0);
  ProgressBar progress(static_cast<int>(n), "frames");
  progress.update(0);
  const auto t0 = Clock::now();
  auto last = t0;
  std::size_t done = 0;
  std::string renderer_name;

  // Per frame: the wall time since the previous batch completed, shared by the
  // batch's frames, plus the frame's own encode-and-write time.
  auto complete = [&](std::size_t first, std::size_t count, const std::vector<double>& write_ms) {
    double writes = 0.0;
    for (double w : write_ms) writes += w;
    const double share = (ms_since(last) - writes) / static_cast<double>(count);
    last = Clock::now();
    for (std::size_t k = 0; k < count; ++k) frame_ms[first + k] = share + write_ms[k];
    done += count;
    progress.update(static_cast<int>(done));
  };

  if (args.server.empty()) {
    RendererOptions ropts;
    ropts.egl.device_index = args.device;
    ropts.egl.platform = args.platform;
    Renderer renderer(ropts);
    renderer_name = renderer.description();
    for (std::size_t at = 0; at < n; at += batch) {
      const std::size_t count = std::min(batch, n - at);
      const std::vector<Camera> part(cams.begin() + static_cast<std::ptrdiff_t>(at),
                                     cams.begin() + static_cast<std::ptrdiff_t>(at + count));
      const auto frames = renderer.render(scene, part);
      std::vector<double> write_ms(count);
      for (std::size_t k = 0; k < count; ++k) {
        const auto w0 = Clock::now();
        write_png(frame_file(args.out, at + k), frames[k].image);
        write_ms[k] = ms_since(w0);
      }
      complete(at, count, write_ms);
    }
  } else {
    client::Endpoint ep;
    try {
      ep = client::parse_endpoint(args.server);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--server", e.what());
    }
    client::Client c;
    const auto timeout = std::chrono::milliseconds(static_cast<long long>(args.timeout_s * 1000));
    c.set_receive_timeout(timeout);
    c.connect(ep.host, ep.port, std::min(timeout, std::chrono::milliseconds(10000)));
    renderer_name = "beamcast-server at " + args.server;
    std::ifstream in(args.scene);
    const nlohmann::json scene_json = nlohmann::json::parse(in);
    // Requests of `batch` cameras, one kept in flight ahead of the one awaited.
    auto send_part = [&](std::size_t at) {
      nlohmann::json cameras = nlohmann::json::array();
      for (std::size_t k = at; k < std::min(n, at + batch); ++k) {
        cameras.push_back(camera_to_json(cams[k]));
      }
      return c.send({{"method", "render"},
                     {"params", {{"scene", scene_json}, {"cameras", cameras},
                                 {"encoding", args.encoding}}}});
    };
    std::vector<nlohmann::json> ids;
    for (std::size_t at = 0; at < n && ids.size() < 2; at += batch) ids.push_back(send_part(at));
    for (std::size_t at = 0, next = 2 * batch; at < n; at += batch, next += batch) {
      const client::Response r = c.receive_for(ids.front());
      ids.erase(ids.begin());
      if (next < n) ids.push_back(send_part(next));
      if (!r.ok) {
        progress.finish();
        print_error("server", r.error);
        return 2;
      }
      const auto frames = client::decode_frames(r);
      const std::size_t count = std::min(batch, n - at);
      if (frames.size() != count) throw std::runtime_error("server sent a wrong number of frames");
      std::vector<double> write_ms(count);
      for (std::size_t k = 0; k < count; ++k) {
        const auto w0 = Clock::now();
        write_bytes(frame_file(args.out, at + k), frames[k].png);
        write_ms[k] = ms_since(w0);
      }
      complete(at, count, write_ms);
    }
  }
  progress.finish();
  const double total_s = ms_since(t0) / 1000.0;
  const TimeSummary t = summarize(frame_ms);
  if (args.json) {
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t i = 0; i < n; ++i) files.push_back(frame_file(args.out, i).string());
    nlohmann::json summary = {{"renderer", renderer_name},
                              {"frames", n},
                              {"files", files},
                              {"total_s", total_s},
                              {"frame_ms", {{"mean", t.mean}, {"p50", t.p50}, {"max", t.max}}}};
    std::printf("%s\n", summary.dump(2).c_str());
  } else {
    std::printf("%zu frames (%dx%d) -> %s/frame_0000.png .. frame_%04zu.png in %.2f s\n", n,
                cams.front().width, cams.front().height, args.out.c_str(), n - 1, total_s);
    std::printf("time per frame: mean %.1f ms, p50 %.1f ms, max %.1f ms (%s, %zu views per batch)\n",
                t.mean, t.p50, t.max, renderer_name.c_str(), batch);
  }
  return 0;
}

}  // namespace beamcast::cli
