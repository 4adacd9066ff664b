// The render fuzzer (docs/fuzzing.md, "The render fuzzer"): generated scenes
// (scene_gen.hpp, case i = seed i) rendered tiny through the real request
// path: an in-process server (protocol parsing, the scene store, cost
// admission, the scheduler, the GL renderer on llvmpipe, the encoders) on a
// loopback port, one TCP connection. Every case must end in
//   - an error reply with a known code, a message and an empty or /-rooted
//     path (never `internal`), or
//   - frames whose linear HDR buffer (read back by a wrapper around the
//     renderer) holds no NaN and no infinity, with no KHR_debug error;
// within max_render_ms plus a margin. A case that takes longer than the hang
// limit stops the run, naming the case; a crash names it from a signal
// handler. Regression files (--replay) are requests with the outcome they
// must have.
//
//   render_fuzz [--first N] [--count N] [--sanitizer-count N] [--max-render-ms MS]
//               [--max-request-cost C] [--overrun-ms MS] [--hang-ms MS]
//               [--artifacts DIR] [--verbose] [--print] [--replay FILE...]
//
// --count (600) cases from seed --first (0); in a sanitizer build at most
// --sanitizer-count (40). --print writes the cases' requests instead of
// running them. --replay runs regression files ({"requests": [...],
// "expect": ...}) instead of generated cases.
//
// BEAMCAST_RENDER_FUZZ_CASES in the environment overrides the count (under a
// sanitizer too). Exit status 0: every case passed; 1: findings (each printed
// with its seed and request); 3: a hang.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "render/gl_debug.hpp"
#include "tests/render_fuzz/scene_gen.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast::render_fuzz {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

#if defined(BEAMCAST_ASAN)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

// ---- What the renderer produced (render worker thread) ---------------------------------

std::mutex g_mu;
std::vector<std::string> g_render_faults;  // non-finite HDR values, KHR_debug errors

void note_fault(std::string what) {
  std::lock_guard lock(g_mu);
  if (g_render_faults.size() < 8) g_render_faults.push_back(std::move(what));
}

std::vector<std::string> take_faults() {
  std::lock_guard lock(g_mu);
  return std::exchange(g_render_faults, {});
}

// The GL renderer, with the linear HDR buffer read back and checked.
class CheckingRenderer final : public FrameRenderer {
 public:
  explicit CheckingRenderer(std::unique_ptr<FrameRenderer> inner) : inner_(std::move(inner)) {}
  std::string description() const override { return inner_->description(); }
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras) override {
    return render(scene, cameras, FrameOptions{});
  }
  std::vector<FrameResult> render(const Scene& scene, const std::vector<Camera>& cameras,
                                  const FrameOptions& options) override {
    FrameOptions o = options;
    o.read_hdr = true;
    std::vector<FrameResult> frames = inner_->render(scene, cameras, o);
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const std::vector<float>& v = frames[f].hdr.rgb;
      const auto bad = std::find_if(v.begin(), v.end(), [](float x) { return !std::isfinite(x); });
      if (bad != v.end()) {
        const std::size_t i = static_cast<std::size_t>(bad - v.begin());
        const int w = std::max(1, frames[f].hdr.width);
        note_fault("frame " + std::to_string(f) + ": HDR value " + std::to_string(*bad) +
                   " at pixel (" + std::to_string((i / 3) % static_cast<std::size_t>(w)) + ", " +
                   std::to_string((i / 3) / static_cast<std::size_t>(w)) + ") channel " +
                   std::to_string(i % 3));
      }
      if (!options.read_hdr) frames[f].hdr = {};
    }
    return frames;
  }
  void fail_next_render_for_test() override { inner_->fail_next_render_for_test(); }

 private:
  std::unique_ptr<FrameRenderer> inner_;
};

// ---- Crash and hang reports ------------------------------------------------------------

char g_case_line[256] = "render_fuzz: no case running\n";

void on_fatal_signal(int sig) {
  const char* head = "\nrender_fuzz: fatal signal during ";
  (void)!write(2, head, std::strlen(head));
  (void)!write(2, g_case_line, std::strlen(g_case_line));
  signal(sig, SIG_DFL);
  raise(sig);
}

void set_current_case(const std::string& what) {
  std::snprintf(g_case_line, sizeof g_case_line, "%s\n", what.c_str());
}

// Ends the process if a case runs past its hang limit.
class Watchdog {
 public:
  explicit Watchdog(int hang_ms) : hang_ms_(hang_ms), thread_([this] { loop(); }) {}
  ~Watchdog() {
    {
      std::lock_guard lock(mu_);
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;
  void arm(std::string what, std::string request) {
    std::lock_guard lock(mu_);
    what_ = std::move(what);
    request_ = std::move(request);
    deadline_ = Clock::now() + std::chrono::milliseconds(hang_ms_);
    armed_ = true;
    cv_.notify_all();
  }
  void disarm() {
    std::lock_guard lock(mu_);
    armed_ = false;
  }

 private:
  void loop() {
    std::unique_lock lock(mu_);
    while (!stop_) {
      if (!armed_) {
        cv_.wait(lock);
        continue;
      }
      if (cv_.wait_until(lock, deadline_) == std::cv_status::timeout && armed_ && Clock::now() >= deadline_) {
        std::cerr << "\nrender_fuzz: HANG: " << what_ << " not answered within " << hang_ms_
                  << " ms\nrequest: " << request_ << std::endl;
        std::_Exit(3);
      }
    }
  }
  int hang_ms_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  bool armed_ = false;
  Clock::time_point deadline_;
  std::string what_;
  std::string request_;
  std::thread thread_;
};

// ---- Judging replies -------------------------------------------------------------------

// Refusals a scene may earn; anything else (internal, busy, shutting_down,
// framing errors) is a finding.
const std::set<std::string> kSceneErrors{
    "missing_field", "wrong_type", "unknown_field", "invalid_value", "out_of_range",
    "not_finite", "degenerate_capsule", "duplicate_name", "conflicting_fields", "limit_exceeded",
    "deadline_exceeded", "forbidden_path", "file_not_found", "bad_mesh", "bad_slim", "bad_volume"};

// "" when the reply is an acceptable error or success shape; else why not.
// `frames` counts the frames of a successful reply.
// `stored`: whether the case's scene.put (if any) stored its scene.
std::string judge_reply(const json& request, const test::Reply& r, bool stored, std::size_t* frames,
                        bool* last_part) {
  *last_part = true;
  const json& j = r.json;
  if (!j.is_object()) return "reply is not an object";
  if (j.value("id", json()) != request.at("id")) return "reply id " + j.value("id", json()).dump() + " is not the request's";
  if (!j.value("ok", false)) {
    if (!j.contains("error") || !j["error"].is_object()) return "error reply without an error object";
    const json& e = j["error"];
    const std::string code = e.value("code", "");
    const std::string message = e.value("message", "");
    if (!e.contains("path") || !e["path"].is_string()) return "error " + code + " without a path";
    const std::string path = e["path"];
    const bool by_id = request.contains("params") && request["params"].contains("scene_id");
    if (!kSceneErrors.count(code) && !(code == "unknown_scene" && by_id && !stored)) {
      return "error code '" + code + "' (" + message + ")";
    }
    if (message.empty()) return "error " + code + " with an empty message";
    if (!path.empty() && path[0] != '/') return "error " + code + " with path '" + path + "'";
    return "";
  }
  if (!j.contains("result") || !j["result"].is_object()) return "ok reply without a result";
  if (request.value("method", "") != "render") return "";
  const json& res = j["result"];
  if (!res.contains("frames") || !res["frames"].is_array() || res["frames"].empty()) {
    return "ok reply without frames";
  }
  for (const json& f : res["frames"]) {
    if (f.value("width", 0) < 1 || f.value("height", 0) < 1) return "frame of size " + f.dump();
    if (f.contains("attachment")) {
      const std::uint64_t off = f["attachment"].value("offset", std::uint64_t{0});
      const std::uint64_t len = f["attachment"].value("length", std::uint64_t{0});
      if (len == 0 || off > r.binary.size() || len > r.binary.size() - off) return "attachment out of the binary part";
    } else if (!f.contains("data_base64")) {
      return "frame without image data";
    }
  }
  *frames += res["frames"].size();
  if (res.contains("stream")) *last_part = res["stream"].value("last", true);
  return "";
}

// What the last request got: "ok" or its error code.
struct CaseResult {
  std::string outcome;
  std::string error_path;  // of an error outcome
  std::vector<std::pair<std::string, std::string>> each;  // every request's outcome and error path
  std::vector<std::string> findings;
  double ms = 0.0;
};

struct Options {
  std::uint64_t first = 0;
  std::uint64_t count = 600;
  std::uint64_t sanitizer_count = 40;
  int max_render_ms = 1500;
  std::int64_t max_request_cost = 600;
  int overrun_ms = 8000;
  int hang_ms = 30000;
  std::string artifacts;
  bool print = false;
  bool verbose = false;  // also the refusals by code and path
  std::vector<std::string> replay;
};

class Runner {
 public:
  explicit Runner(const Options& o) : o_(o), watchdog_(o.hang_ms) {
    ServerConfig c;
    c.max_render_ms = o.max_render_ms;
    c.max_request_cost = o.max_request_cost;
    RendererFactory gl = gl_renderer_factory({});
    server_ = std::make_unique<test::LocalServer>(
        c, [gl] { return std::make_unique<CheckingRenderer>(gl()); });
    conn_ = std::make_unique<test::Conn>(server_->port(), o.hang_ms / 1000 + 5);
  }

  CaseResult run(const std::string& name, const std::vector<json>& requests) {
    CaseResult out;
    take_faults();
    std::vector<std::string> stored;
    for (std::size_t k = 0; k < requests.size(); ++k) {
      const json& req = requests[k];
      set_current_case(name + " request " + std::to_string(k) + ": " + req.dump().substr(0, 160));
      watchdog_.arm(name, req.dump());
      const auto r0 = Clock::now();
      conn_->send(req);
      std::size_t frames = 0;
      bool last = false;
      std::string why;
      test::Reply reply;
      while (!last && why.empty()) {
        reply = conn_->recv();
        why = judge_reply(req, reply, !stored.empty(), &frames, &last);
      }
      watchdog_.disarm();
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - r0).count();
      if (!why.empty()) out.findings.push_back(req.value("method", "") + ": " + why);
      const bool ok = reply.json.value("ok", false);
      out.each.emplace_back(ok ? "ok" : reply.json["error"].value("code", "?"),
                            ok ? "" : reply.json["error"].value("path", ""));
      if (req.value("method", "") == "scene.put" && ok) stored.push_back(req["params"]["scene_id"]);
      if (k + 1 == requests.size()) {
        out.outcome = ok ? "ok" : reply.json["error"].value("code", "?");
        if (!ok) out.error_path = reply.json["error"].value("path", "");
        out.ms = ms;
        if (ms > o_.max_render_ms + o_.overrun_ms) {
          out.findings.push_back("answered after " + std::to_string(static_cast<int>(ms)) +
                                 " ms, past max_render_ms " + std::to_string(o_.max_render_ms) +
                                 " + " + std::to_string(o_.overrun_ms));
        }
      }
    }
    for (std::string& f : take_faults()) out.findings.push_back("render: " + f);
    for (const std::string& id : stored) {
      const test::Reply d = conn_->call({{"id", "delete"}, {"method", "scene.delete"}, {"params", {{"scene_id", id}}}});
      if (!d.json.value("ok", false)) out.findings.push_back("scene.delete failed: " + d.json.dump());
    }
    return out;
  }

  // The server still answers a ping and renders a small scene.
  std::string alive() {
    const test::Reply p = conn_->call({{"id", "ping"}, {"method", "ping"}});
    if (!p.json.value("ok", false)) return "ping: " + p.json.dump();
    const test::Reply r = conn_->call({{"id", "alive"}, {"method", "render"}, {"params", {{"scene", test::tiny_scene(8)}}}});
    if (!r.json.value("ok", false)) return "small render: " + r.json.dump();
    return "";
  }

 private:
  Options o_;
  Watchdog watchdog_;
  std::unique_ptr<test::LocalServer> server_;
  std::unique_ptr<test::Conn> conn_;
};

void report(const std::string& name, const std::vector<json>& requests, const CaseResult& r,
            const std::string& artifacts) {
  std::cerr << "FINDING " << name << " (outcome " << r.outcome << ", " << static_cast<int>(r.ms) << " ms):\n";
  for (const std::string& f : r.findings) std::cerr << "  " << f << "\n";
  for (const json& q : requests) std::cerr << "  request: " << q.dump() << "\n";
  if (!artifacts.empty()) {
    std::filesystem::create_directories(artifacts);
    std::string file = name;
    std::replace(file.begin(), file.end(), ' ', '_');
    std::ofstream(std::filesystem::path(artifacts) / (file + ".json"))
        << json{{"finding", r.findings}, {"requests", requests}}.dump(1) << "\n";
  }
}

int replay(Runner& runner, const Options& o) {
  int failed = 0;
  for (const std::string& file : o.replay) {
    std::ifstream in(file);
    const json doc = json::parse(in);
    const std::vector<json> requests = doc.at("requests").get<std::vector<json>>();
    CaseResult r = runner.run(file, requests);
    // "expect": {"code": C, "path": P} or {"ok": true} for the last request,
    // or an array of them, one per request.
    json expect = doc.value("expect", json::object());
    if (!expect.is_array()) {
      json each = json::array();
      for (std::size_t k = 0; k + 1 < requests.size(); ++k) each.push_back(json::object());
      each.push_back(expect);
      expect = each;
    }
    for (std::size_t k = 0; k < expect.size() && k < r.each.size(); ++k) {
      const json& e = expect[k];
      const auto& [got, path] = r.each[k];
      const std::string want = e.value("ok", false) ? "ok" : e.value("code", got);
      if (got != want || (e.contains("path") && path != e["path"])) {
        r.findings.push_back("request " + std::to_string(k) + ": expected " + e.dump() + ", got " + got +
                             (path.empty() ? "" : " at " + path));
      }
    }
    if (!r.findings.empty()) {
      report(file, requests, r, o.artifacts);
      ++failed;
    } else {
      std::cout << "ok " << file << " (" << r.outcome << (r.error_path.empty() ? "" : " at " + r.error_path)
                << ", " << static_cast<int>(r.ms) << " ms)\n";
    }
  }
  const std::string dead = runner.alive();
  if (!dead.empty()) {
    std::cerr << "server not alive after the replays: " << dead << "\n";
    ++failed;
  }
  return failed == 0 ? 0 : 1;
}

int fuzz(Runner& runner, const Options& o) {
  std::map<std::string, int> outcomes;
  std::map<std::string, int> refusals;
  std::vector<double> times;
  int failed = 0;
  const auto t0 = Clock::now();
  for (std::uint64_t s = o.first; s < o.first + o.count; ++s) {
    const FuzzCase c = make_case(s);
    const std::string name = "case " + std::to_string(s);
    const CaseResult r = runner.run(name, c.requests);
    ++outcomes[r.outcome];
    if (o.verbose && r.ms > o.max_render_ms) {
      std::cout << "slow: " << name << " " << r.outcome << " " << static_cast<int>(r.ms) << " ms\n";
    }
    if (o.verbose && r.outcome != "ok") {
      std::string where;  // the path with indices dropped
      for (char ch : r.error_path) {
        if (!std::isdigit(static_cast<unsigned char>(ch))) where += ch;
      }
      ++refusals[r.outcome + " " + where];
    }
    times.push_back(r.ms);
    if (!r.findings.empty()) {
      report(name, c.requests, r, o.artifacts);
      ++failed;
    }
    if ((s - o.first + 1) % 100 == 0) {
      const std::string dead = runner.alive();
      if (!dead.empty()) {
        std::cerr << "server not alive after " << name << ": " << dead << "\n";
        return 1;
      }
    }
  }
  const std::string dead = runner.alive();
  if (!dead.empty()) {
    std::cerr << "server not alive at the end: " << dead << "\n";
    ++failed;
  }
  const double total_s = std::chrono::duration<double>(Clock::now() - t0).count();
  std::sort(times.begin(), times.end());
  auto pct = [&](double p) {
    return times.empty() ? 0.0 : times[std::min(times.size() - 1, static_cast<std::size_t>(p * static_cast<double>(times.size())))];
  };
  std::cout << "render_fuzz: cases " << o.first << ".." << (o.first + o.count - 1) << " (" << o.count
            << ") in " << total_s << " s; per case p50 " << pct(0.5) << " ms, p99 " << pct(0.99)
            << " ms, max " << (times.empty() ? 0.0 : times.back()) << " ms; findings " << failed << "\n  outcomes:";
  for (const auto& [k, v] : outcomes) std::cout << " " << k << " " << v;
  std::cout << std::endl;
  for (const auto& [k, v] : refusals) std::cout << "  " << v << " " << k << "\n";
  return failed == 0 ? 0 : 1;
}

}  // namespace
}  // namespace beamcast::render_fuzz

int main(int argc, char** argv) {
  using namespace beamcast::render_fuzz;
  Options o;
  bool count_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--first") o.first = std::stoull(next());
    else if (a == "--count") { o.count = std::stoull(next()); count_given = true; }
    else if (a == "--sanitizer-count") o.sanitizer_count = std::stoull(next());
    else if (a == "--max-render-ms") o.max_render_ms = std::stoi(next());
    else if (a == "--max-request-cost") o.max_request_cost = std::stoll(next());
    else if (a == "--overrun-ms") o.overrun_ms = std::stoi(next());
    else if (a == "--hang-ms") o.hang_ms = std::stoi(next());
    else if (a == "--artifacts") o.artifacts = next();
    else if (a == "--print") o.print = true;
    else if (a == "--verbose") o.verbose = true;
    else if (a == "--replay") {
      while (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) o.replay.emplace_back(argv[++i]);
    } else {
      std::cerr << "unknown argument " << a << " (see the comment at the top of tests/render_fuzz/render_fuzz.cpp)\n";
      return 2;
    }
  }
  if (kSanitized && !count_given) o.count = o.sanitizer_count;
  if (kSanitized) o.count = std::min(o.count, o.sanitizer_count);
  if (const char* env = std::getenv("BEAMCAST_RENDER_FUZZ_CASES")) o.count = std::stoull(env);
  if (o.print) {
    for (std::uint64_t s = o.first; s < o.first + o.count; ++s) {
      for (const auto& q : make_case(s).requests) std::cout << q.dump() << "\n";
    }
    return 0;
  }
  // As the GL test binaries (tests/common/gl_test_main.cpp): debug contexts
  // and validated draws; driver errors are findings of the case they came in.
  setenv("BEAMCAST_GL_DEBUG", "1", 0);
  setenv("BEAMCAST_GL_VALIDATE", "1", 0);
  beamcast::set_gl_debug_sink([](const beamcast::GlDebugMessage& m) {
    if (m.type == "error" || m.type == "undefined behavior") note_fault("KHR_debug: " + beamcast::format_gl_debug_message(m));
  });
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) signal(sig, on_fatal_signal);
  int rc = 0;
  try {
    Runner runner(o);
    rc = o.replay.empty() ? fuzz(runner, o) : replay(runner, o);
  } catch (const std::exception& e) {
    // The connection broke (the server closed it, or a read timed out).
    std::cerr << "render_fuzz: " << e.what() << " during " << g_case_line;
    rc = 1;
  }
  beamcast::set_gl_debug_sink({});
  return rc;
}
