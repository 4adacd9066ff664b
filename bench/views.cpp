#include "bench/views.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "bench/accuracy_report.hpp"
#include "client/client.hpp"
#include "protocol/data_dir.hpp"
#include "protocol/rigs.hpp"
#include "protocol/scene_json.hpp"
#include "render/renderer.hpp"

namespace beamcast::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double num(const json& j, const char* key) {
  const auto it = j.find(key);
  return it != j.end() && it->is_number() ? it->get<double>() : 0.0;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A beamcast-server child on a free port; SIGTERM on destruction.
class ServerProcess {
 public:
  explicit ServerProcess(const fs::path& binary) {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      // K pipelined requests must all be admitted; 64 covers K = 36. No
      // HTTP listener: the default port (7879) is another server's in a
      // parallel test run (ctest -j: "bind: Address already in use").
      execl(binary.c_str(), binary.c_str(), "--port", "0", "--http-port", "-1", "--no-demo",
            "--max-inflight-per-connection", "64", "--max-inflight-total", "128",
            static_cast<char*>(nullptr));
      std::perror("exec beamcast-server");
      _exit(127);
    }
    close(fds[1]);
    std::string line;
    char c = 0;
    while (read(fds[0], &c, 1) == 1 && c != '\n') line += c;
    close(fds[0]);
    // "beamcast-server listening on HOST:PORT"
    const auto at = line.rfind(' ');
    if (line.find("listening on") == std::string::npos || at == std::string::npos) {
      throw std::runtime_error("beamcast-server did not start (" + binary.string() + "): " + line);
    }
    address_ = line.substr(at + 1);
  }
  ~ServerProcess() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  const std::string& address() const { return address_; }

 private:
  pid_t pid_ = -1;
  std::string address_;
};

struct Row {
  int k = 0;
  // one_request, k_requests, renderer_batched, renderer_batched_sync (batches
  // read back synchronously: Readback::kSynchronous; renderer_batched is
  // Readback::kPipelined, whatever the device),
  // renderer_single
  std::string mode;
  int round = 0;
  double e2e_ms = 0;     // client: first request written -> last response read
  double render_ms = 0;  // server render call(s), summed over requests
  double gpu_ms = 0;     // GL timestamps, summed over GPU batches
  double readback_ms = 0;
  double encode_ms = 0;  // server encode wall, summed over requests
  // Renderer rows only (not on the wire): where the renderer's wall time went,
  // summed over GPU batches (render/renderer.hpp, BatchTiming).
  double submit_ms = 0, readback_wait_ms = 0, readback_copy_ms = 0;
};

// Sums a response's per-frame GPU figures, counting each GPU batch once.
void add_frames(const json& result, Row* row) {
  std::map<int, bool> seen;
  for (const json& f : result.value("frames", json::array())) {
    const json& b = f.value("gpu_batch", json::object());
    const int index = b.value("index", -1);
    if (seen[index]) continue;
    seen[index] = true;
    row->gpu_ms += num(b, "gpu_ms");
    row->readback_ms += num(b, "readback_ms");
  }
  const json& t = result.value("timings", json::object());
  row->render_ms += num(t, "render_ms");
  row->encode_ms += num(t, "encode_ms");
}

json render_params(const json& cameras) {
  return {{"scene_id", "views_bench"}, {"cameras", cameras}, {"encoding", "binary"}};
}

Row one_request(client::Client& c, const json& cameras, int k) {
  Row row{k, "one_request"};
  const auto t0 = Clock::now();
  const client::Response r = c.call("render", render_params(cameras));
  row.e2e_ms = ms_since(t0);
  if (!r.ok) throw std::runtime_error("render failed: " + r.error.message);
  add_frames(r.result(), &row);
  return row;
}

Row k_requests(client::Client& c, const json& cameras, int k, int window) {
  Row row{k, "k_requests"};
  const auto t0 = Clock::now();
  std::vector<json> ids;
  std::size_t sent = 0, received = 0;
  const std::size_t n = cameras.size();
  while (received < n) {
    while (sent < n && sent - received < static_cast<std::size_t>(window)) {
      ids.push_back(c.send({{"method", "render"},
                            {"params", render_params(json::array({cameras[sent]}))}}));
      ++sent;
    }
    const client::Response r = c.receive_for(ids[received]);
    if (!r.ok) throw std::runtime_error("render failed: " + r.error.message);
    add_frames(r.result(), &row);
    ++received;
  }
  row.e2e_ms = ms_since(t0);
  return row;
}

Row renderer_run(Renderer& renderer, const Scene& scene, const std::vector<Camera>& cams, int k,
                 bool batch, bool pipelined = true) {
  Row row{k, !batch ? "renderer_single" : pipelined ? "renderer_batched" : "renderer_batched_sync"};
  const auto t0 = Clock::now();
  const auto frames =
      renderer.render(scene, cams,
                      FrameOptions{.batch = batch,
                                   .readback = pipelined ? Readback::kPipelined
                                                         : Readback::kSynchronous});
  row.e2e_ms = ms_since(t0);
  row.render_ms = row.e2e_ms;
  std::map<int, bool> seen;
  for (const FrameResult& f : frames) {
    if (seen[f.batch.index]) continue;
    seen[f.batch.index] = true;
    row.gpu_ms += f.batch.gpu_ms;
    row.readback_ms += f.batch.readback_ms;
    row.submit_ms += f.batch.submit_ms;
    row.readback_wait_ms += f.batch.readback_wait_ms;
    row.readback_copy_ms += f.batch.readback_copy_ms;
  }
  return row;
}

std::string run_plot(const fs::path& out) {
  const fs::path script = find_data_dir("bench") / "plot_views.py";
  const std::string cmd = shell_quote(python_interpreter()) + " " + shell_quote(script.string()) +
                          " " + shell_quote((out / "views.csv").string()) + " " +
                          shell_quote((out / "views.png").string());
  const int status = std::system(cmd.c_str());
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "plot_views.py failed";
  return "";
}

}  // namespace

int run_views(const ViewsOptions& opts) {
  const int size = opts.size > 0 ? opts.size : (opts.quick ? 128 : 512);
  const int rounds = opts.rounds > 0 ? opts.rounds : (opts.quick ? 1 : 3);
  std::vector<int> ks = opts.views;
  if (ks.empty()) ks = opts.quick ? std::vector<int>{1, 2, 4} : std::vector<int>{1, 2, 4, 8, 16, 36};
  fs::create_directories(opts.out);

  // The paper's 10-set scene; K cameras on the orbit through its camera.
  const fs::path file = find_data_dir("examples") / "paper_10sets.json";
  std::ifstream in(file);
  json scene_json = json::parse(in);
  scene_json["cameras"][0]["width"] = size;
  scene_json["cameras"][0]["height"] = size;
  const Scene scene = parse_scene(scene_json, SceneLoadOptions{});

  std::unique_ptr<ServerProcess> child;
  std::string address = opts.server;
  if (address.empty()) {
    fs::path binary = opts.server_binary;
    if (binary.empty()) binary = fs::read_symlink("/proc/self/exe").parent_path() / "beamcast-server";
    child = std::make_unique<ServerProcess>(binary);
    address = child->address();
  }
  const client::Endpoint ep = client::parse_endpoint(address);
  client::Client c;
  c.set_receive_timeout(std::chrono::milliseconds(600000));
  c.connect(ep.host, ep.port);
  const client::Response hello = c.hello("beamcast-bench-views");
  if (!hello.ok) throw std::runtime_error("hello failed: " + hello.error.message);
  const int window = std::max(
      1, hello.result().value("limits", json::object()).value("max_inflight_per_connection", 16));
  const client::Response put = c.scene_put("views_bench", scene_json);
  if (!put.ok) throw std::runtime_error("scene.put failed: " + put.error.message);
  const std::string server_renderer = hello.result().value("renderer", "");
  std::fprintf(stderr, "bench views: server %s (%s), %dx%d, K = ", address.c_str(),
               server_renderer.c_str(), size, size);
  for (int k : ks) std::fprintf(stderr, "%d ", k);
  std::fprintf(stderr, ", %d rounds, pipelining window %d\n", rounds, window);

  std::unique_ptr<Renderer> renderer;
  if (opts.renderer) {
    RendererOptions ro;
    ro.egl = opts.egl;
    renderer = std::make_unique<Renderer>(ro);
  }

  // Warm-up: programs, tables, the multi-view variants, both paths.
  {
    const auto cams = rig_from_spec("orbit:2", scene);
    json cj = json::array();
    for (const Camera& cam : cams) cj.push_back(camera_to_json(cam));
    one_request(c, cj, 2);
    k_requests(c, cj, 2, window);
    if (renderer) {
      renderer_run(*renderer, scene, cams, 2, true);
      renderer_run(*renderer, scene, cams, 2, true, false);
      renderer_run(*renderer, scene, cams, 2, false);
    }
  }

  std::vector<Row> rows;
  for (int round = 0; round < rounds; ++round) {
    for (int k : ks) {
      const auto cams = rig_from_spec("orbit:" + std::to_string(k), scene);
      json cj = json::array();
      for (const Camera& cam : cams) cj.push_back(camera_to_json(cam));
      // Alternate which variant goes first, so drift in the machine's load
      // does not favour one.
      std::vector<Row> got;
      if (round % 2 == 0) {
        got.push_back(one_request(c, cj, k));
        got.push_back(k_requests(c, cj, k, window));
      } else {
        got.push_back(k_requests(c, cj, k, window));
        got.push_back(one_request(c, cj, k));
      }
      if (renderer) {
        // Pipelined and synchronous read-back alternate too.
        if (round % 2 == 0) {
          got.push_back(renderer_run(*renderer, scene, cams, k, true));
          got.push_back(renderer_run(*renderer, scene, cams, k, true, false));
        } else {
          got.push_back(renderer_run(*renderer, scene, cams, k, true, false));
          got.push_back(renderer_run(*renderer, scene, cams, k, true));
        }
        got.push_back(renderer_run(*renderer, scene, cams, k, false));
      }
      for (Row& r : got) {
        r.round = round;
        std::fprintf(stderr, "  round %d K=%-2d %-17s e2e %9.1f ms  render %9.1f  gpu %9.1f\n",
                     round, k, r.mode.c_str(), r.e2e_ms, r.render_ms, r.gpu_ms);
        rows.push_back(r);
      }
    }
  }

  // CSV: every measurement.
  {
    std::ofstream csv(opts.out / "views.csv");
    csv << "k,mode,round,e2e_ms,render_ms,gpu_ms,readback_ms,encode_ms,submit_ms,"
           "readback_wait_ms,readback_copy_ms\n";
    for (const Row& r : rows) {
      csv << r.k << ',' << r.mode << ',' << r.round << ',' << r.e2e_ms << ',' << r.render_ms << ','
          << r.gpu_ms << ',' << r.readback_ms << ',' << r.encode_ms << ',' << r.submit_ms << ','
          << r.readback_wait_ms << ',' << r.readback_copy_ms << '\n';
    }
  }
  // Markdown: medians per K and mode, and the ratios that matter.
  auto med = [&](int k, const std::string& mode, double Row::*field) {
    std::vector<double> v;
    for (const Row& r : rows)
      if (r.k == k && r.mode == mode) v.push_back(r.*field);
    return median(v);
  };
  std::ofstream md(opts.out / "views.md");
  md << "Server: " << server_renderer << "; " << size << "x" << size << ", " << rounds
     << " round(s), medians; pipelining window " << window << ".\n\n";
  md << "| K | one request e2e ms | K requests e2e ms | ratio | one: render / gpu / read-back / "
        "encode ms | K req: render / gpu / read-back / encode ms (sums) |";
  if (renderer) {
    md << " renderer batched / single ms (gpu) | renderer batched: submit / read-back wait / "
          "copy ms | renderer batched, synchronous read-back: ms, submit / wait / copy ms |";
  }
  md << "\n|---|---|---|---|---|---|";
  if (renderer) md << "---|---|---|";
  md << "\n";
  char buf[512];
  for (int k : ks) {
    const double a = med(k, "one_request", &Row::e2e_ms), b = med(k, "k_requests", &Row::e2e_ms);
    std::snprintf(buf, sizeof buf, "| %d | %.1f | %.1f | %.2f | %.1f / %.1f / %.1f / %.1f | %.1f / %.1f / %.1f / %.1f |",
                  k, a, b, b > 0 ? a / b : 0.0, med(k, "one_request", &Row::render_ms),
                  med(k, "one_request", &Row::gpu_ms), med(k, "one_request", &Row::readback_ms),
                  med(k, "one_request", &Row::encode_ms), med(k, "k_requests", &Row::render_ms),
                  med(k, "k_requests", &Row::gpu_ms), med(k, "k_requests", &Row::readback_ms),
                  med(k, "k_requests", &Row::encode_ms));
    md << buf;
    if (renderer) {
      std::snprintf(buf, sizeof buf, " %.1f (%.1f) / %.1f (%.1f) |",
                    med(k, "renderer_batched", &Row::e2e_ms), med(k, "renderer_batched", &Row::gpu_ms),
                    med(k, "renderer_single", &Row::e2e_ms), med(k, "renderer_single", &Row::gpu_ms));
      md << buf;
      std::snprintf(buf, sizeof buf, " %.1f / %.1f / %.1f |",
                    med(k, "renderer_batched", &Row::submit_ms),
                    med(k, "renderer_batched", &Row::readback_wait_ms),
                    med(k, "renderer_batched", &Row::readback_copy_ms));
      md << buf;
      std::snprintf(buf, sizeof buf, " %.1f, %.1f / %.1f / %.1f |",
                    med(k, "renderer_batched_sync", &Row::e2e_ms),
                    med(k, "renderer_batched_sync", &Row::submit_ms),
                    med(k, "renderer_batched_sync", &Row::readback_wait_ms),
                    med(k, "renderer_batched_sync", &Row::readback_copy_ms));
      md << buf;
    }
    md << "\n";
  }
  md.close();
  std::fprintf(stderr, "bench views: wrote %s/views.csv and views.md\n", opts.out.c_str());
  if (opts.plots) {
    const std::string err = run_plot(opts.out);
    if (!err.empty()) {
      std::fprintf(stderr, "bench views: %s\n", err.c_str());
      return 1;
    }
  }
  return 0;
}

}  // namespace beamcast::bench
