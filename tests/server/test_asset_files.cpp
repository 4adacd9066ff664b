// Asset files through a running server (issue 43, item 5): the preview's
// example route under the scene files' path rules, and OBJ / SLIM files far
// over their limits refused quickly, in bounded memory, while another
// connection's ping is answered. GL-free (fake renderer): nothing renders.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/server/fake_renderer.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

class TempAssets {
 public:
  TempAssets() {
    dir_ = fs::temp_directory_path() /
           ("beamcast_assets_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempAssets() { fs::remove_all(dir_); }
  const fs::path& dir() const { return dir_; }

 private:
  fs::path dir_;
};

struct HttpAnswer {
  int status = 0;
  std::string body;
};

// A plain HTTP/1.1 GET (Connection: close): status and body.
HttpAnswer http_get(unsigned short port, const std::string& target) {
  test::Conn c(port, 20);
  c.send_raw("GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  std::string all;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::recv(c.native_handle(), buf, sizeof buf, 0);
    if (n <= 0) break;
    all.append(buf, static_cast<std::size_t>(n));
  }
  HttpAnswer a;
  if (all.size() > 12) a.status = std::stoi(all.substr(9, 3));
  const auto end = all.find("\r\n\r\n");
  if (end != std::string::npos) a.body = all.substr(end + 4);
  return a;
}

ServerConfig config_for(const fs::path& assets) {
  ServerConfig c;
  c.assets_dir = assets;
  c.http_port = 0;
  return c;
}

TEST(AssetFiles, ExampleRouteRefusesLinksOutSpecialFilesAndOversizedOnes) {
  TempAssets assets;
  const fs::path& d = assets.dir();
  std::ofstream(d / "ok.json") << R"({"cameras": []})";
  std::ofstream(d / "big.json") << std::string(3000, ' ');
  fs::create_symlink("/etc/passwd", d / "passwd.json");
  fs::create_symlink("/proc/self/environ", d / "environ.json");
  ASSERT_EQ(::mkfifo((d / "fifo.json").c_str(), 0600), 0);
  ServerConfig c = config_for(d);
  c.max_message_bytes = 2048;  // the example route's byte limit
  test::LocalServer s(c, test::fake_renderer_factory(std::make_shared<test::FakeRendererControl>()));

  const HttpAnswer ok = http_get(s.http_port(), "/api/examples/ok.json");
  EXPECT_EQ(ok.status, 200);
  EXPECT_EQ(ok.body, R"({"cameras": []})");
  for (const char* link : {"passwd.json", "environ.json"}) {
    const HttpAnswer a = http_get(s.http_port(), std::string("/api/examples/") + link);
    EXPECT_EQ(a.status, 403) << link << ": " << a.body.substr(0, 200);
    EXPECT_NE(a.body.find("resolves to a file outside the assets directory"), std::string::npos)
        << a.body.substr(0, 200);
  }
  const HttpAnswer fifo = http_get(s.http_port(), "/api/examples/fifo.json");
  EXPECT_EQ(fifo.status, 403);
  EXPECT_NE(fifo.body.find("is not a regular file"), std::string::npos) << fifo.body;
  const HttpAnswer big = http_get(s.http_port(), "/api/examples/big.json");
  EXPECT_EQ(big.status, 413);
  EXPECT_NE(big.body.find("3000 bytes, over the 2048 bytes that max_message_bytes allows"),
            std::string::npos) << big.body;
  EXPECT_EQ(http_get(s.http_port(), "/api/examples/missing.json").status, 404);
  // The list offers only what the route serves.
  const json list = json::parse(http_get(s.http_port(), "/api/scenes").body);
  EXPECT_EQ(list["examples"], json({"big.json", "ok.json"}));
}

// Peak resident memory (VmHWM) of this process, which hosts the server, in MiB
// since reset_peak().
double peak_mib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1.0;
}
void reset_peak() { std::ofstream("/proc/self/clear_refs") << "5"; }

struct Refusal {
  json reply;
  double ms = 0.0;          // the request's answer
  double ping_ms = 0.0;     // another connection's ping, sent right after it
  double peak_mib = 0.0;    // growth of the peak resident size over the request
};

Refusal timed_scene_put(unsigned short port, const json& scene) {
  test::Conn a(port, 60), b(port, 60);
  b.call({{"id", 0}, {"method", "ping"}});  // connected and served once
  reset_peak();
  const double base = peak_mib();
  Refusal r;
  const auto t0 = Clock::now();
  a.send({{"id", 1}, {"method", "scene.put"}, {"params", {{"scene_id", "s"}, {"scene", scene}}}});
  const auto p0 = Clock::now();
  const test::Reply ping = b.call({{"id", 2}, {"method", "ping"}});
  r.ping_ms = std::chrono::duration<double, std::milli>(Clock::now() - p0).count();
  EXPECT_TRUE(ping.json.value("ok", false)) << ping.json;
  r.reply = a.recv().json;
  r.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  r.peak_mib = peak_mib() - base;
  return r;
}

// Bounds for both files below. Time: the fixed server stops at a stat (OBJ)
// or after 0.6 MB of JSON (SLIM), 2-100 ms; 500 ms leaves room for a loaded
// 2-core machine and is far below the whole-file parse the old readers did
// (1-3 s here). Memory: 48 MiB is under the size of either file, so a reader
// that held the file's text once, let alone its parsed document (tinyobj's
// arrays, or nlohmann's DOM at ~25 bytes a byte), crosses it. The file is
// generated in the test's temp dir (about 0.3 s).
constexpr double kMaxMs = 500.0;
constexpr double kMaxPeakMib = 48.0;

void expect_quick_bounded_refusal(const Refusal& r, const std::string& words) {
  ASSERT_FALSE(r.reply.value("ok", true)) << r.reply.dump().substr(0, 300);
  EXPECT_EQ(r.reply["error"]["code"], "limit_exceeded") << r.reply;
  EXPECT_EQ(r.reply["error"]["path"], "/params/scene/occluders/0/file") << r.reply;
  EXPECT_NE(r.reply["error"]["message"].get<std::string>().find(words), std::string::npos)
      << r.reply;
#if !defined(BEAMCAST_ASAN)
  // Not in the Debug + sanitizer build: its JSON parsing runs some 10x
  // slower (the SLIM refusal took 948 ms there, about what the old reader
  // took in the optimized build), so time tells nothing; and ASan's
  // quarantine keeps freed blocks resident. What it checks there: the
  // refusal, its code, path and message, and no memory error.
  EXPECT_LT(r.ms, kMaxMs);
  EXPECT_LT(r.ping_ms, kMaxMs);
  EXPECT_LT(r.peak_mib, kMaxPeakMib);
#endif
  std::printf("refused in %.1f ms, ping beside it %.1f ms, peak +%.1f MiB\n", r.ms, r.ping_ms,
              r.peak_mib);
}

json scene_with(const json& occluder) {
  json s = test::tiny_scene(8);
  s["occluders"] = json::array({occluder});
  return s;
}

TEST(AssetFiles, OversizedObjIsRefusedQuicklyInBoundedMemoryWhileOthersAreAnswered) {
  TempAssets assets;
  {
    // 400 000 vertices and 800 000 faces: 24 MB.
    std::ofstream out(assets.dir() / "big.obj", std::ios::binary);
    for (int i = 0; i < 400000; ++i) out << "v 0.125 0.25 " << i << "\n";
    for (int i = 0; i < 800000; ++i) out << "f " << 1 + i / 2 << " " << 2 + i / 2 << " " << 3 + i / 2 << "\n";
  }
  ServerConfig c = config_for(assets.dir());
  c.scene_limits.max_mesh_triangles = 1000;
  test::LocalServer s(c, test::fake_renderer_factory(std::make_shared<test::FakeRendererControl>()));
  expect_quick_bounded_refusal(
      timed_scene_put(s.port(), scene_with({{"type", "mesh"}, {"file", "big.obj"}})),
      "max_mesh_triangles = 1000");
}

TEST(AssetFiles, SlimJsonOverItsSphereLimitIsRefusedQuicklyInBoundedMemory) {
  TempAssets assets;
  const std::string sphere = R"({"center":[0,0,0],"radius":1,"coefficients":[0,0,0,0,0,0]})";
  {
    // 160 000 spheres (9.8 MB), under the byte limit of 10 000 spheres (10.2 MB).
    std::ofstream out(assets.dir() / "big.json", std::ios::binary);
    out << R"({"format":"beamcast-slim","version":1,"spheres":[)" << sphere;
    for (int i = 1; i < 160000; ++i) out << "," << sphere;
    out << "]}";
  }
  ServerConfig c = config_for(assets.dir());
  c.scene_limits.max_slim_spheres = 10000;
  test::LocalServer s(c, test::fake_renderer_factory(std::make_shared<test::FakeRendererControl>()));
  json slim = scene_with({{"type", "slim"}, {"file", "big.json"}});
  expect_quick_bounded_refusal(timed_scene_put(s.port(), slim), "max_slim_spheres = 10000");
}

// A legal mesh file is parsed off the network thread: a ping on another
// connection is answered while a scene.put of a 720 000-triangle OBJ (the
// limit is 1 000 000) is being parsed. Before, the parse ran on the one
// network thread and the ping waited for it.
TEST(AssetFiles, PingIsAnsweredWhileALegalMeshFileIsParsed) {
  TempAssets assets;
  {
    // A 600 x 600 grid of quads: 361 201 vertices, 720 000 triangles, 24 MB.
    constexpr int n = 600;
    std::ofstream out(assets.dir() / "grid.obj", std::ios::binary);
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) out << "v " << j << " 0 " << i << "\n";
    }
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const int a = i * (n + 1) + j + 1;
        out << "f " << a << " " << a + 1 << " " << a + n + 2 << "\nf " << a << " " << a + n + 2
            << " " << a + n + 1 << "\n";
      }
    }
  }
  test::LocalServer s(config_for(assets.dir()),
                      test::fake_renderer_factory(std::make_shared<test::FakeRendererControl>()));
  const Refusal r =
      timed_scene_put(s.port(), scene_with({{"type", "mesh"}, {"file", "grid.obj"}}));
  EXPECT_TRUE(r.reply.value("ok", false)) << r.reply.dump().substr(0, 300);
  std::printf("scene.put of the mesh %.1f ms, ping beside it %.1f ms\n", r.ms, r.ping_ms);
#if !defined(BEAMCAST_ASAN)
  // The parse must be long enough to tell (measured 250-400 ms here), and
  // the ping at most a quarter of it: on the network thread the ping waited
  // for nearly all of it; beside it, it waits for a scheduler turn of the
  // loaded 2-core machine (measured 0.2-2 ms).
  ASSERT_GT(r.ms, 100.0) << "the parse was too quick to tell";
  EXPECT_LT(r.ping_ms, r.ms / 4) << "the ping waited for the mesh file's parse";
#endif
}

}  // namespace
}  // namespace beamcast
