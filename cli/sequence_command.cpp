// `beamcast render --rig SPEC | --path FILE`: a turntable, cube map, stereo
// pair or keyframed animation rendered to numbered PNGs (frame_0000.png ...),
// locally or on a server, in batches of views, with progress on stderr and a
// per-frame time summary.
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "cli/server_options.hpp"
#include "client/client.hpp"
#include "client/resilient_client.hpp"
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

fs::path frame_file(const SequenceArgs& args, std::size_t i) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04zu.png", i);
  return fs::path(args.out) / (args.prefix + name);
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

// The frames of a sequence rendered on one or more servers (--server A,B,C,
// each with --connections workers; a balancer's address counts as one): the
// job is cut into batches of views, and each worker takes the next batch,
// renders it by a scene id it stored on its connection, and hands the
// frames over by their position, so the numbered files come out in order
// whichever server rendered them. A worker whose server fails after its
// retries (client::ResilientClient) puts its batch back for the others and
// stops; the job fails only when every worker has, or when a server refuses
// a request (a bad scene fails the same way everywhere).
struct RemoteResult {
  std::string error;        // empty: every frame was delivered
  std::string description;  // "beamcast-server at A, B"
  nlohmann::json servers;   // per worker: endpoint, batches, frames, retries, error
};

using DeliverFn = std::function<void(std::size_t first, const std::vector<client::RenderedFrame>& frames,
                                     double request_ms)>;

// The job's copy of the scene off each server (best effort: a server that
// has gone keeps it until it is evicted or restarts).
void delete_scene(const std::vector<client::Endpoint>& endpoints, const std::string& scene_id,
                  const SequenceArgs& args) {
  for (const client::Endpoint& ep : endpoints) {
    try {
      client::Client c;
      connect_to_server(c, ep, args.token, std::min(args.timeout_s, 10.0));
      c.scene_delete(scene_id);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "beamcast: could not delete scene %s: %s\n", scene_id.c_str(), e.what());
    }
  }
}

RemoteResult render_on_servers(const SequenceArgs& args, const nlohmann::json& scene_json,
                               const std::vector<Camera>& cams, std::size_t batch,
                               const DeliverFn& deliver, const std::function<void(std::size_t)>& on_part) {
  std::vector<client::Endpoint> endpoints;
  std::string list = args.server;
  for (std::size_t at = 0; at <= list.size();) {
    const std::size_t comma = std::min(list.find(',', at), list.size());
    try {
      endpoints.push_back(client::parse_endpoint(list.substr(at, comma - at)));
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--server", e.what());
    }
    at = comma + 1;
  }
  RemoteResult out;
  out.description = "beamcast-server at " + args.server;

  std::mutex mu;
  std::deque<std::size_t> waiting;  // first view of each batch not yet delivered
  for (std::size_t at = 0; at < cams.size(); at += batch) waiting.push_back(at);
  std::size_t delivered = 0, in_flight = 0, batches = waiting.size();
  std::condition_variable changed;
  std::string refusal;  // a server's error answer: the job's end

  auto budget = std::make_shared<client::RetryBudget>();
  // The user's stored scene, or a copy of the file stored for this job (and
  // deleted after it).
  const bool temporary = args.scene_id.empty();
  const std::string scene_id = temporary ? "render-" + std::to_string(::getpid()) : args.scene_id;
  const auto timeout = std::chrono::milliseconds(static_cast<long long>(args.timeout_s * 1000));
  struct Worker {
    std::string endpoint;
    std::size_t batches = 0, frames = 0;
    bool stored = false;  // the job's copy of the scene is on its server
    client::RetryStats stats;
    std::string error;
  };
  std::vector<Worker> report;
  std::vector<std::thread> threads;
  const int per_endpoint = std::max(1, args.connections);
  report.resize(endpoints.size() * static_cast<std::size_t>(per_endpoint));
  for (std::size_t w = 0; w < report.size(); ++w) {
    const client::Endpoint& ep = endpoints[w / static_cast<std::size_t>(per_endpoint)];
    threads.emplace_back([&, w, ep] {
      Worker& me = report[w];
      client::ResilientOptions opts;
      opts.connect_timeout = std::min(timeout, std::chrono::milliseconds(10000));
      opts.receive_timeout = timeout;
      opts.token = args.token;
      opts.seed = w + 1;
      client::ResilientClient c(ep, budget, opts);
      me.endpoint = c.endpoint();
      std::optional<std::size_t> mine;
      try {
        if (temporary) {
          c.scene_put(scene_id, scene_json);
          me.stored = true;
        }
        for (;;) {
          {
            // Idle workers wait while batches are out: one may come back.
            std::unique_lock lock(mu);
            changed.wait(lock, [&] { return !waiting.empty() || in_flight == 0 || !refusal.empty(); });
            if (waiting.empty() || !refusal.empty()) break;
            mine = waiting.front();
            waiting.pop_front();
            ++in_flight;
          }
          const std::size_t at = *mine;
          const std::size_t count = std::min(batch, cams.size() - at);
          client::RenderRequest req;
          req.scene_id = scene_id;
          req.encoding = args.encoding;
          req.cameras = nlohmann::json::array();
          for (std::size_t k = at; k < at + count; ++k) req.cameras.push_back(camera_to_json(cams[k]));
          // Streamed: each GPU slice's frames come as they finish, so the
          // progress moves within a batch.
          req.stream = true;
          req.on_part = [&, count](int, const std::vector<client::RenderedFrame>& part) {
            if (on_part) on_part(std::min(part.size(), count));
          };
          const auto t0 = Clock::now();
          const client::RenderResult r = c.render(req);
          if (!r.ok) {
            std::lock_guard lock(mu);
            refusal = me.endpoint + ": [" + r.error.code + "] " + r.error.path +
                      (r.error.path.empty() ? "" : ": ") + r.error.message;
            mine.reset();
            --in_flight;
            changed.notify_all();
            break;
          }
          if (r.frames.size() != count) throw std::runtime_error("server sent a wrong number of frames");
          deliver(at, r.frames, ms_since(t0));
          mine.reset();
          std::lock_guard lock(mu);
          --in_flight;
          delivered += 1;
          me.batches += 1;
          me.frames += count;
          changed.notify_all();
        }
      } catch (const client::RequestRefused& e) {
        // A wrong token or a scene the server refuses: the same everywhere.
        std::lock_guard lock(mu);
        me.error = e.what();
        refusal = e.what();
        if (mine) --in_flight;
        changed.notify_all();
      } catch (const std::exception& e) {
        // Its server is gone (after retries): the batch goes back for the
        // other workers.
        std::lock_guard lock(mu);
        me.error = e.what();
        if (mine) {
          waiting.push_front(*mine);
          --in_flight;
        }
        changed.notify_all();
      }
      me.stats = c.stats();
    });
  }
  for (auto& t : threads) t.join();
  if (temporary) {
    // Off the servers that took it (one worker per server suffices).
    std::vector<client::Endpoint> holders;
    for (std::size_t w = 0; w < report.size(); ++w) {
      const client::Endpoint& ep = endpoints[w / static_cast<std::size_t>(per_endpoint)];
      if (report[w].stored && (holders.empty() || holders.back().port != ep.port ||
                               holders.back().host != ep.host)) {
        holders.push_back(ep);
      }
    }
    delete_scene(holders, scene_id, args);
  }
  // A worker that stopped before the queue drained leaves work: the others
  // took it, unless every one failed.
  std::string failures;
  for (const Worker& w : report) {
    out.servers.push_back({{"server", w.endpoint},
                           {"batches", w.batches},
                           {"frames", w.frames},
                           {"retries", w.stats.retries},
                           {"scene_reputs", w.stats.reputs},
                           {"connections", w.stats.connections},
                           {"error", w.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(w.error)}});
    if (!w.error.empty()) failures += "\n  " + w.endpoint + ": " + w.error;
  }
  if (!refusal.empty()) {
    out.error = "refused: " + refusal;
  } else if (delivered < batches) {
    out.error = std::to_string(batches - delivered) + " of " + std::to_string(batches) +
                " batches not rendered: every server failed" + failures;
  }
  return out;
}

// A stored scene's JSON, by scene.get on the first server.
nlohmann::json fetch_stored_scene(const SequenceArgs& args) {
  const std::string first = args.server.substr(0, args.server.find(','));
  client::Client c;
  connect_to_server(c, first, args.token, args.timeout_s);
  const client::Response r = c.call("scene.get", {{"scene_id", args.scene_id}});
  if (!r.ok) throw ProtocolError(r.error);
  return r.result().value("scene", nlohmann::json::object());
}

}  // namespace

int run_sequence(const SequenceArgs& args) {
  SceneLoadOptions load;
  load.assets_dir = args.assets.empty() ? fs::path(args.scene).parent_path() : fs::path(args.assets);
  if (load.assets_dir.empty()) load.assets_dir = ".";
  Scene scene;
  nlohmann::json scene_json;  // with --server: what is stored there
  std::vector<Camera> cams;
  const std::string source = args.scene_id.empty() ? args.scene : "scene " + args.scene_id;
  try {
    if (!args.scene_id.empty()) {
      // The rig is framed here, from the stored scene's cameras and content;
      // the frames are rendered from the stored scene itself.
      scene_json = fetch_stored_scene(args);
      scene = parse_scene(scene_json, load);
    } else {
      scene = load_scene_file(args.scene, load);
      if (!args.server.empty()) scene_json = nlohmann::json::parse(std::ifstream(args.scene));
    }
    apply_frame_choice(args.choice, &scene.cameras);
  } catch (const ProtocolError& e) {
    print_error(source, e.info());
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
  nlohmann::json servers_json;  // with --server: frames, retries and errors per server

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
        write_png(frame_file(args, at + k), frames[k].image);
        write_ms[k] = ms_since(w0);
      }
      complete(at, count, write_ms);
    }
  } else {
    std::mutex mu;  // guards the progress bar and the frame times
    std::size_t received = 0;  // frames in the parts so far (a retried part counts again)
    const RemoteResult remote = render_on_servers(
        args, scene_json, cams, batch,
        [&](std::size_t at, const std::vector<client::RenderedFrame>& frames, double request_ms) {
          std::vector<double> write_ms(frames.size());
          for (std::size_t k = 0; k < frames.size(); ++k) {
            const auto w0 = Clock::now();
            write_bytes(frame_file(args, at + k), frames[k].png);
            write_ms[k] = ms_since(w0);
          }
          std::lock_guard lock(mu);
          for (std::size_t k = 0; k < frames.size(); ++k) {
            frame_ms[at + k] = request_ms / static_cast<double>(frames.size()) + write_ms[k];
          }
          done += frames.size();
        },
        [&](std::size_t frames) {
          std::lock_guard lock(mu);
          received += frames;
          progress.update(static_cast<int>(std::min(received, n)));
        });
    progress.update(static_cast<int>(n));
    if (!remote.error.empty()) {
      progress.finish();
      std::fprintf(stderr, "beamcast: %s\n", remote.error.c_str());
      return 2;
    }
    renderer_name = remote.description;
    servers_json = remote.servers;
  }
  progress.finish();
  const double total_s = ms_since(t0) / 1000.0;
  const TimeSummary t = summarize(frame_ms);
  if (args.json) {
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t i = 0; i < n; ++i) files.push_back(frame_file(args, i).string());
    nlohmann::json summary = {{"renderer", renderer_name},
                              {"frames", n},
                              {"files", files},
                              {"total_s", total_s},
                              {"frame_ms", {{"mean", t.mean}, {"p50", t.p50}, {"max", t.max}}}};
    if (!servers_json.is_null()) summary["servers"] = servers_json;
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
