// The `beamcast` subcommands that talk to beamcast-server: `render --server`,
// `ping` and `stats`. They use beamcast_client only, never render/.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/server_options.hpp"
#include "client/client.hpp"
#include "client/resilient_client.hpp"
#include "protocol/errors.hpp"
#include "render/image.hpp"

namespace beamcast::cli {
namespace {

using client::Client;

void print_error(const ErrorInfo& e) {
  std::fprintf(stderr, "beamcast: server error [%s] %s%s%s\n", e.code.c_str(), e.path.c_str(),
               e.path.empty() ? "" : ": ", e.message.c_str());
}

double number(const nlohmann::json& obj, const char* key) {
  const auto it = obj.find(key);
  return it != obj.end() && it->is_number() ? it->get<double>() : 0.0;
}

void write_file(const std::filesystem::path& file, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(file, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!f) throw std::runtime_error("cannot write " + file.string());
}

// The file stem of a frame. The server names frames as the offline path does
// (camera name, else camera_<index>); a name that is not a safe file name (a
// confused or hostile server) falls back to camera_<index>.
std::string frame_stem(const client::RenderedFrame& f) {
  const std::string& n = f.camera;
  const bool safe =
      !n.empty() && n.size() <= 64 && n != "." && n != ".." &&
      std::all_of(n.begin(), n.end(), [](char ch) {
        return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.' || ch == '-';
      });
  return safe ? n : "camera_" + std::to_string(f.index);
}

// --camera and --size on a stored scene: its cameras (scene.get), chosen
// and sized, sent as the render's camera list.
int choose_stored_cameras(const RemoteRenderArgs& args, nlohmann::json* cameras) {
  Client c;
  connect_to_server(c, args.server, args.token, args.timeout_s);
  const client::Response r = c.call("scene.get", {{"scene_id", args.scene_id}});
  if (!r.ok) {
    print_error(r.error);
    return 2;
  }
  nlohmann::json scene = r.result().value("scene", nlohmann::json::object());
  try {
    apply_frame_choice(args.choice, &scene);
  } catch (const ProtocolError& e) {
    std::fprintf(stderr, "beamcast: scene %s: %s\n", args.scene_id.c_str(), e.what());
    return 2;
  }
  *cameras = scene.value("cameras", nlohmann::json::array());
  return 0;
}

// `beamcast scenes`: the stored ids, one a line, then a count; with
// --delete, each deleted (an unknown id is an error, exit 2).
void run_scenes(const std::string& server, const std::string& token,
                const std::vector<std::string>& remove, double timeout_s) {
  Client c;
  connect_to_server(c, server, token, timeout_s);
  bool failed = false;
  for (const std::string& id : remove) {
    const client::Response r = c.scene_delete(id);
    if (!r.ok) {
      print_error(r.error);
      failed = true;
    } else {
      std::printf("deleted %s\n", id.c_str());
    }
  }
  if (failed) throw CLI::RuntimeError(2);
  if (!remove.empty()) return;
  const client::Response r = c.call("scene.list");
  if (!r.ok) {
    print_error(r.error);
    throw CLI::RuntimeError(2);
  }
  const nlohmann::json& res = r.result();
  for (const auto& id : res.value("scenes", nlohmann::json::array())) {
    if (id.is_string()) std::printf("%s\n", id.get<std::string>().c_str());
  }
  std::printf("%zu scene(s), %.0f bytes\n", res.value("scenes", nlohmann::json::array()).size(),
              number(res, "bytes"));
}

}  // namespace

int run_remote_render(const RemoteRenderArgs& args) {
  namespace fs = std::filesystem;
  client::RenderRequest req;
  req.encoding = args.encoding;
  if (!args.scene_id.empty()) {
    req.scene_id = args.scene_id;
    if (args.choice.any()) {
      const int rc = choose_stored_cameras(args, &req.cameras);
      if (rc != 0) return rc;
    }
  } else {
    // Sent as is: the server validates it (meshes come from the server's --assets).
    std::ifstream in(args.scene);
    try {
      req.scene = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
      std::fprintf(stderr, "beamcast: %s: %s\n", args.scene.c_str(), e.what());
      return 2;
    }
    try {
      apply_frame_choice(args.choice, &req.scene);
    } catch (const ProtocolError& e) {
      std::fprintf(stderr, "beamcast: %s: %s\n", args.scene.c_str(), e.what());
      return 2;
    }
  }

  // Retried on a new connection if one drops (a server behind a balancer
  // may die mid-render); a server's error answer is not retried.
  client::Endpoint ep;
  try {
    ep = client::parse_endpoint(args.server);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--server", e.what());
  }
  client::ResilientOptions opts;
  opts.receive_timeout = std::chrono::milliseconds(static_cast<long long>(args.timeout_s * 1000));
  opts.connect_timeout = std::min(opts.receive_timeout, std::chrono::milliseconds(10000));
  opts.token = args.token;
  if (args.frame_format != "png") opts.frame_format = args.frame_format;
  client::ResilientClient c(ep, nullptr, opts);
  const client::RenderResult r = c.render(req);
  if (!r.ok) {
    print_error(r.error);
    return 2;
  }
  fs::create_directories(args.out);

  nlohmann::json summary;
  summary["server"] = args.server;
  if (req.scene_id.empty()) {
    summary["scene"] = args.scene;
  } else {
    summary["scene_id"] = req.scene_id;
  }
  summary["passes"] = r.passes;
  summary["frames"] = nlohmann::json::array();
  for (const client::RenderedFrame& f : r.frames) {
    const bool raw = !f.samples.empty();
    const fs::path file = fs::path(args.out) / (args.prefix + frame_stem(f) + ".png");
    if (raw) {
      // Raw samples from the server: the PNG is made here, on the client's cores.
      write_png(file, Image{f.width, f.height, f.bit_depth, f.samples});
    } else {
      write_file(file, f.png);
    }
    nlohmann::json jf = {{"camera", f.camera},
                         {"file", file.string()},
                         {"width", f.width},
                         {"height", f.height},
                         {"format", f.format},
                         {"bytes", f.png.size()}};
    jf.update(f.timings);
    summary["frames"].push_back(jf);
    if (!args.json) {
      std::printf("%-24s %4dx%-4d gpu %7.3f ms", file.filename().c_str(), f.width, f.height,
                  number(f.timings, "gpu_ms"));
      if (const auto p = f.timings.find("pass_ms"); p != f.timings.end() && p->is_object()) {
        std::printf(" (");
        bool first = true;
        for (const auto& [name, ms] : p->items()) {
          std::printf("%s%s %.3f", first ? "" : ", ", name.c_str(),
                      ms.is_number() ? ms.get<double>() : 0.0);
          first = false;
        }
        std::printf(")");
      }
      std::printf("  read-back %.2f ms  encode %.2f ms\n", number(f.timings, "readback_ms"),
                  number(f.timings, "encode_ms"));
    }
  }
  summary["timings"] = r.timings;
  summary["client"] = {{"e2e_ms", r.e2e_ms}, {"network_ms", r.network_ms}};
  if (args.json) {
    std::printf("%s\n", summary.dump(2).c_str());
  } else {
    const nlohmann::json& t = r.timings;
    std::printf(
        "server: queue %.2f ms, render %.2f ms, read-back %.2f ms, encode %.2f ms, "
        "total %.2f ms\n",
        number(t, "queue_ms"), number(t, "render_ms"), number(t, "readback_ms"),
        number(t, "encode_ms"), r.server_ms);
    std::printf("client: end-to-end %.2f ms, network %.2f ms (end-to-end - server)\n", r.e2e_ms,
                r.network_ms);
  }
  return 0;
}

void add_server_commands(CLI::App& app) {
  struct PingArgs {
    std::string server;
    std::string token;
    int count = 4;
    double timeout_s = 10;
  };
  auto ping = std::make_shared<PingArgs>();
  CLI::App* pc = app.add_subcommand("ping", "Round-trip times to a beamcast-server");
  add_server_option(pc, &ping->server);
  add_token_option(pc, &ping->token);
  pc->add_option("--count,-c", ping->count, "Number of pings")->check(CLI::Range(1, 1000000));
  pc->add_option("--timeout", ping->timeout_s, "Seconds to wait for each reply")
      ->check(CLI::PositiveNumber);
  pc->callback([ping] {
    Client c;
    connect_to_server(c, ping->server, ping->token, ping->timeout_s);
    std::vector<double> rtts;
    for (int i = 0; i < ping->count; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const client::Response r = c.ping({{"seq", i}});
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (!r.ok) {
        print_error(r.error);
        throw CLI::RuntimeError(2);
      }
      rtts.push_back(ms);
      std::printf("ping %d from %s: %.3f ms\n", i + 1, c.peer().c_str(), ms);
    }
    double sum = 0;
    for (double v : rtts) sum += v;
    std::printf("%zu pings: min %.3f ms, avg %.3f ms, max %.3f ms\n", rtts.size(),
                *std::min_element(rtts.begin(), rtts.end()), sum / static_cast<double>(rtts.size()),
                *std::max_element(rtts.begin(), rtts.end()));
  });

  struct StatsArgs {
    std::string server;
    std::string token;
    double timeout_s = 10;
  };
  auto stats = std::make_shared<StatsArgs>();
  CLI::App* sc = app.add_subcommand("stats", "Print a beamcast-server's counters as JSON");
  add_server_option(sc, &stats->server);
  add_token_option(sc, &stats->token);
  sc->add_option("--timeout", stats->timeout_s, "Seconds to wait for the reply")
      ->check(CLI::PositiveNumber);
  sc->callback([stats] {
    Client c;
    connect_to_server(c, stats->server, stats->token, stats->timeout_s);
    const client::Response r = c.stats();
    if (!r.ok) {
      print_error(r.error);
      throw CLI::RuntimeError(2);
    }
    std::printf("%s\n", r.result().dump(2).c_str());
  });

  struct ScenesArgs {
    std::string server;
    std::string token;
    std::vector<std::string> remove;
    double timeout_s = 10;
  };
  auto scenes = std::make_shared<ScenesArgs>();
  CLI::App* lc = app.add_subcommand(
      "scenes", "List the scenes stored on a beamcast-server (most recently used first), or delete some");
  add_server_option(lc, &scenes->server);
  add_token_option(lc, &scenes->token);
  lc->add_option("--delete", scenes->remove, "Delete this stored scene (repeatable)");
  lc->add_option("--timeout", scenes->timeout_s, "Seconds to wait for each reply")
      ->check(CLI::PositiveNumber);
  lc->callback([scenes] { run_scenes(scenes->server, scenes->token, scenes->remove, scenes->timeout_s); });
}

}  // namespace beamcast::cli
