// Integration tests: a real beamcast server (GL render worker on llvmpipe) on
// an ephemeral port in this process, spoken to over TCP.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <thread>

#include "protocol/base64.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/slim_io.hpp"
#include "render/image.hpp"
#include "render/pass_plan.hpp"
#include "render/renderer.hpp"
#include "server/server.hpp"
#include "tests/server/test_client.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::Conn;
using test::Reply;
namespace fs = std::filesystem;

json read_example(const std::string& name) {
  std::ifstream in(fs::path(BEAMCAST_SOURCE_DIR) / "examples" / (name + ".json"));
  return json::parse(in);
}

json small_scene(int size = 64) {
  return {{"beams",
           {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"density", "abe"}},
            {{"type", "capsule"}, {"p0", {0, 0, 0}}, {"p1", {2, 1, 0}}, {"radius", 0.4}}}},
          {"cameras", {{{"position", {0, 1, 5}}, {"target", {0.5, 0.3, 0}}, {"width", size}, {"height", size}}}}};
}

json render_req(json id, json scene) {
  return {{"id", std::move(id)}, {"method", "render"}, {"params", {{"scene", std::move(scene)}}}};
}

std::string error_code(const Reply& r) { return r.json.at("error").at("code"); }
std::string error_path(const Reply& r) { return r.json.at("error").at("path"); }

class TestServer {
 public:
  explicit TestServer(ServerConfig c = {}) {
    c.port = 0;
    if (c.assets_dir.empty()) c.assets_dir = fs::path(BEAMCAST_SOURCE_DIR) / "examples";
    server_ = std::make_unique<Server>(c, gl_renderer_factory({}));
    port_ = server_->start();
    thread_ = std::thread([this] { server_->run(false); });
  }
  ~TestServer() {
    server_->shutdown();
    thread_.join();
  }
  unsigned short port() const { return port_; }
  ServerCore& core() { return server_->core(); }
  // Healthy: a fresh connection gets a ping answered.
  bool healthy() {
    Conn c(port_, 10);
    return c.call({{"id", "health"}, {"method", "ping"}}).json.value("ok", false);
  }

 private:
  std::unique_ptr<Server> server_;
  unsigned short port_ = 0;
  std::thread thread_;
};

Image frame_png(const Reply& r, std::size_t i) { return decode_png(test::frame_bytes(r, i)); }

TEST(Server, HelloReportsProtocolCapabilitiesAndLimits) {
  TestServer s;
  Conn c(s.port());
  Reply r = c.call({{"id", 1}, {"method", "hello"}, {"params", {{"protocol", 1}}}});
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(r.json["id"], 1);
  EXPECT_EQ(r.json["result"]["protocol"], 1);
  EXPECT_EQ(r.json["result"]["limits"]["max_width"], 4096);
  EXPECT_FALSE(r.json["result"]["renderer"].get<std::string>().empty());
  r = c.call({{"id", 2}, {"method", "hello"}, {"params", {{"protocol", 2}}}});
  EXPECT_EQ(error_code(r), "unsupported_protocol");
  EXPECT_EQ(error_path(r), "/params/protocol");
}

TEST(Server, RemoteRenderIsPixelIdenticalToOfflineRender) {
  TestServer s;
  json scene = read_example("beam_occluder");
  scene["cameras"][0]["width"] = 160;
  scene["cameras"][0]["height"] = 120;
  Conn c(s.port());
  const Reply r = c.call(render_req("a", scene));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(r.json["result"]["passes"], json(plan_passes(parse_scene(scene, SceneLoadOptions{}))));
  const Image remote = frame_png(r, 0);

  SceneLoadOptions opts;
  opts.assets_dir = fs::path(BEAMCAST_SOURCE_DIR) / "examples";
  Renderer offline;
  const auto frames = offline.render(parse_scene(scene, opts));
  // Same renderer code on the same device: the frames must match exactly.
  EXPECT_EQ(compare_levels(remote, frames[0].image).max_abs, 0);
}

// Lit scenes (issue 14) over the wire: the response lists the photon passes
// and each frame's photons, a camera-only change traces nothing (the
// render worker's cache), and bad lights, materials and photon counts get
// errors with their paths while the server keeps serving.
TEST(Server, LitScenesReportPhotonsAndRefuseBadLightsWithPaths) {
  TestServer s;
  json scene = read_example("cornell_box");
  scene["cameras"][0]["width"] = 64;
  scene["cameras"][0]["height"] = 64;
  scene["gi"] = {{"photons", 5000}};
  Conn c(s.port());
  Reply r = c.call(render_req(1, scene));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(r.json["result"]["passes"],
            json({"gbuffer", "direct", "photons", "gi_resolve", "tonemap"}));
  const RenderResponse first = test::render_result(r);
  ASSERT_TRUE(first.frames[0].photons);
  EXPECT_GT(first.frames[0].photons->count, 0);
  EXPECT_GT(first.frames[0].photons->trace_ms, 0.0);
  scene["cameras"][0]["position"][0] = 270.0;
  r = c.call(render_req(2, scene));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(test::render_result(r).frames[0].photons->trace_ms, 0.0);
  // A beam-only render has no photons member.
  r = c.call(render_req(3, small_scene(16)));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_FALSE(test::render_result(r).frames[0].photons);

  json bad = scene;
  bad["lights"] = {{{"type", "point"}, {"position", {278, 500, 280}}, {"power", -5}}};
  r = c.call(render_req(4, bad));
  EXPECT_EQ(error_code(r), "out_of_range");
  EXPECT_EQ(error_path(r), "/params/scene/lights/0/power");
  bad = scene;
  bad["occluders"][5]["material"] = {{"type", "glass"}, {"ior", 0}};
  r = c.call(render_req(5, bad));
  EXPECT_EQ(error_code(r), "out_of_range");
  EXPECT_EQ(error_path(r), "/params/scene/occluders/5/material/ior");
  bad = scene;
  bad["gi"] = {{"photons", 4000001}};  // the server's max_photons is 4 000 000
  r = c.call(render_req(6, bad));
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/scene/gi/photons");
  EXPECT_TRUE(s.healthy());
  r = c.call(render_req(7, scene));
  EXPECT_TRUE(r.json["ok"]) << r.json;
}

// SLIM surfaces (issue 16): bad spheres and bad model files are refused with
// their paths, and the server keeps serving; a good one renders the slim
// passes.
TEST(Server, SlimSurfacesRenderAndBadOnesAreRefusedWithPaths) {
  const fs::path dir = fs::temp_directory_path() / ("beamcast_slim_server_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  SlimSphere flat;
  flat.radius = 1.0;
  const std::string bin = slim_to_binary({flat, flat});
  std::ofstream(dir / "ok.bslm", std::ios::binary) << bin;
  std::ofstream(dir / "cut.bslm", std::ios::binary) << bin.substr(0, bin.size() - 10);
  ServerConfig config;
  config.assets_dir = dir;
  TestServer s(config);
  Conn c(s.port());
  json sphere = {{"center", {0, 0, 0}}, {"radius", 1.0}, {"coefficients", {-0.3, 0, -0.3, 0, 0, 0.5}}};
  json scene = {{"occluders", {{{"type", "slim"}, {"spheres", json::array({sphere})}}}},
                {"cameras", {{{"position", {0, 3, 0.5}}, {"target", {0, 0, 0}}, {"width", 32}, {"height", 32}}}}};
  Reply r = c.call(render_req(1, scene));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(r.json["result"]["passes"],
            json({"surfaces", "slim_depth", "slim_accumulate", "slim_resolve", "tonemap"}));
  auto refused = [&](json occluder, const std::string& code, const std::string& path) {
    json bad = scene;
    bad["occluders"][0] = std::move(occluder);
    const Reply e = c.call(render_req(2, bad));
    EXPECT_EQ(error_code(e), code) << e.json;
    EXPECT_EQ(error_path(e), path) << e.json;
  };
  json negative = sphere;
  negative["radius"] = -1;
  refused({{"type", "slim"}, {"spheres", json::array({negative})}}, "out_of_range", "/params/scene/occluders/0/spheres/0/radius");
  json rotation = sphere;
  rotation["rotation"] = {0, 0, 0, 0};
  refused({{"type", "slim"}, {"spheres", json::array({rotation})}}, "invalid_value",
          "/params/scene/occluders/0/spheres/0/rotation");
  refused({{"type", "slim"}, {"file", "../outside.bslm"}}, "forbidden_path", "/params/scene/occluders/0/file");
  refused({{"type", "slim"}, {"file", "cut.bslm"}}, "bad_slim", "/params/scene/occluders/0/file");
  EXPECT_TRUE(s.healthy());
  scene["occluders"][0] = {{"type", "slim"}, {"file", "ok.bslm"}};
  r = c.call(render_req(3, scene));
  EXPECT_TRUE(r.json["ok"]) << r.json;
  fs::remove_all(dir);
}

TEST(Server, PipelinedRequestsAnswerWithTheirIds) {
  TestServer s;
  Conn c(s.port());
  std::set<json> expected;
  for (int i = 0; i < 8; ++i) {
    c.send(render_req("r" + std::to_string(i), small_scene(32 + 8 * i)));
    expected.insert("r" + std::to_string(i));
    c.send({{"id", 100 + i}, {"method", "ping"}, {"params", {{"n", i}}}});
    expected.insert(100 + i);
  }
  std::set<json> got;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    Reply r = c.recv();
    ASSERT_TRUE(r.json["ok"]) << r.json;
    got.insert(r.json["id"]);
    if (r.json["id"].is_string()) {
      const int k = std::stoi(r.json["id"].get<std::string>().substr(1));
      EXPECT_EQ(frame_png(r, 0).width, 32 + 8 * k);  // the frame answers its own request
    } else {
      EXPECT_EQ(r.json["result"]["echo"]["n"], r.json["id"].get<int>() - 100);
    }
  }
  EXPECT_EQ(got, expected);
}

TEST(Server, MultiCameraRequestReturnsEveryFrame) {
  TestServer s;
  Conn c(s.port());
  const json scene = read_example("multi_camera");
  const Reply r = c.call(render_req(7, scene));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  const std::vector<RenderFrame> frames = test::render_result(r).frames;
  ASSERT_EQ(frames.size(), scene["cameras"].size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Image img = frame_png(r, i);
    EXPECT_EQ(frames[i].camera, scene["cameras"][i]["name"]);
    EXPECT_EQ(img.width, scene["cameras"][i]["width"]);
    EXPECT_EQ(img.height, scene["cameras"][i]["height"]);
    EXPECT_EQ(img.bit_depth, 16);
  }
}

TEST(Server, Base64EncodingCarriesTheSamePng) {
  TestServer s;
  Conn c(s.port());
  const Reply bin = c.call(render_req(1, small_scene()));
  json req = render_req(2, small_scene());
  req["params"]["encoding"] = "base64";
  const Reply b64 = c.call(req);
  ASSERT_TRUE(b64.json["ok"]) << b64.json;
  EXPECT_TRUE(b64.binary.empty());
  const RenderFrame f = test::render_result(b64).frames.at(0);
  ASSERT_TRUE(f.data_base64);
  EXPECT_FALSE(f.attachment);
  const std::string& text = *f.data_base64;
  EXPECT_EQ(text.substr(0, 8), "iVBORw0K");  // base64 of the PNG signature
  // The same scene, the same encoder: the same bytes either way.
  EXPECT_EQ(base64_decode(text), test::frame_bytes(bin));
}

TEST(Server, StoredScenesPutUpdateRenderDeleteAndEvict) {
  ServerConfig cfg;
  cfg.max_scenes = 2;
  TestServer s(cfg);
  Conn c(s.port());
  Reply r = c.call({{"id", 1}, {"method", "scene.put"}, {"params", {{"scene_id", "a"}, {"scene", small_scene()}}}});
  ASSERT_TRUE(r.json["ok"]) << r.json;
  // A preview client sends only a camera pose.
  json pose = {{"position", {3, 1, 3}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 40}};
  r = c.call({{"id", 2}, {"method", "render"}, {"params", {{"scene_id", "a"}, {"cameras", json::array({pose})}}}});
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(frame_png(r, 0).width, 48);
  const Image before = frame_png(r, 0);
  // Merge patch: a brighter scene renders differently.
  r = c.call({{"id", 3}, {"method", "scene.update"},
              {"params", {{"scene_id", "a"}, {"patch", {{"output", {{"exposure", 4.0}}}}}}}});
  ASSERT_TRUE(r.json["ok"]) << r.json;
  r = c.call({{"id", 4}, {"method", "render"}, {"params", {{"scene_id", "a"}, {"cameras", json::array({pose})}}}});
  EXPECT_GT(compare_levels(frame_png(r, 0), before).max_abs, 10);
  // A patch that breaks the scene is refused with the path, the scene stays.
  r = c.call({{"id", 5}, {"method", "scene.update"},
              {"params", {{"scene_id", "a"}, {"patch", {{"output", {{"exposure", -1}}}}}}}});
  EXPECT_EQ(error_code(r), "out_of_range");
  EXPECT_EQ(error_path(r), "/params/patch/output/exposure");
  // Eviction: a third scene pushes out the least recently used one.
  c.call({{"id", 6}, {"method", "scene.put"}, {"params", {{"scene_id", "b"}, {"scene", small_scene()}}}});
  r = c.call({{"id", 7}, {"method", "scene.put"}, {"params", {{"scene_id", "c"}, {"scene", small_scene()}}}});
  EXPECT_EQ(r.json["result"]["evicted"], json({"a"}));
  r = c.call({{"id", 8}, {"method", "render"}, {"params", {{"scene_id", "a"}}}});
  EXPECT_EQ(error_code(r), "unknown_scene");
  r = c.call({{"id", 9}, {"method", "scene.delete"}, {"params", {{"scene_id", "b"}}}});
  EXPECT_TRUE(r.json["ok"]);
  r = c.call({{"id", 10}, {"method", "scene.delete"}, {"params", {{"scene_id", "b"}}}});
  EXPECT_EQ(error_code(r), "unknown_scene");
}

// Each class of malformed input gets its documented error, and the connection
// stays usable where the framing allows.
TEST(Server, MalformedInputGetsDocumentedErrors) {
  ServerConfig cfg;
  cfg.max_message_bytes = 8192;
  TestServer s(cfg);
  Conn c(s.port());
  auto still_usable = [&c] {
    return c.call({{"id", "p"}, {"method", "ping"}}).json.value("ok", false);
  };
  c.send_text("{not json");
  Reply r = c.recv();
  EXPECT_EQ(error_code(r), "bad_json");
  EXPECT_TRUE(r.json["id"].is_null());
  EXPECT_TRUE(still_usable());

  c.send_text("[1, 2]");
  EXPECT_EQ(error_code(c.recv()), "bad_json");
  c.send_text(R"({"method": "ping"})");
  r = c.recv();
  EXPECT_EQ(error_code(r), "bad_request");
  EXPECT_EQ(error_path(r), "/id");
  c.send_text(R"({"id": 1, "method": 42})");
  EXPECT_EQ(error_path(c.recv()), "/method");
  EXPECT_TRUE(still_usable());

  r = c.call({{"id", 2}, {"method", "render"}, {"params", {{"scene", 5}}}});
  EXPECT_EQ(error_code(r), "wrong_type");
  EXPECT_EQ(error_path(r), "/params/scene");
  json scene = small_scene();
  scene["beams"][0]["radius"] = "big";
  r = c.call(render_req(3, scene));
  EXPECT_EQ(error_code(r), "wrong_type");
  EXPECT_EQ(error_path(r), "/params/scene/beams/0/radius");

  c.send_text(R"({"id": 4, "method": "render", "params": {"scene": {"beams": [{"type": "sphere", "center": [0, 0, 1e999], "radius": 1}], "cameras": [{}]}}})");
  EXPECT_EQ(error_code(c.recv()), "not_finite");
  EXPECT_TRUE(still_usable());

  r = c.call({{"id", 5}, {"method", "teleport"}});
  EXPECT_EQ(error_code(r), "unknown_method");
  EXPECT_EQ(r.json["id"], 5);

  // Oversized: refused from the header, body skipped, connection still usable.
  c.send_text(R"({"id": 6, "method": "ping", "params": {"pad": ")" + std::string(20000, 'x') + "\"}}");
  EXPECT_EQ(error_code(c.recv()), "message_too_large");
  EXPECT_TRUE(still_usable());

  // Mesh paths may not leave the assets directory.
  for (const char* file : {"../CMakeLists.txt", "/etc/passwd", "meshes/../../README.md"}) {
    json sc = small_scene();
    sc["occluders"] = {{{"type", "mesh"}, {"file", file}}};
    r = c.call(render_req(7, sc));
    EXPECT_EQ(error_code(r), "forbidden_path") << file;
    EXPECT_EQ(error_path(r), "/params/scene/occluders/0/file") << file;
  }
  EXPECT_TRUE(still_usable());

  // Not a Beamcast frame at all: one error, then the server closes. (An
  // HTTP request gets an HTTP answer instead: tests/python/test_cli_first_hour.py.)
  c.send_raw(std::string("JUNK0000garbage bytes here"));
  r = c.recv();
  EXPECT_EQ(error_code(r), "bad_framing");
  EXPECT_TRUE(c.closed_by_peer());
  EXPECT_TRUE(s.healthy());
  EXPECT_GE(s.core().stats.errors("bad_framing"), 1u);
}

TEST(Server, SceneAndRequestLimitsAreEnforced) {
  ServerConfig cfg;
  cfg.scene_limits.max_beams = 3;
  cfg.scene_limits.max_cameras = 4;
  cfg.scene_limits.max_width = 256;
  cfg.scene_limits.max_pixels = 200 * 200;
  cfg.scene_limits.max_mesh_triangles = 100;
  TestServer s(cfg);
  Conn c(s.port());
  json sc = small_scene();
  sc["cameras"][0]["width"] = 300;
  Reply r = c.call(render_req(1, sc));
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/scene/cameras/0/width");

  sc = small_scene();
  sc["cameras"][0]["width"] = 250;
  sc["cameras"][0]["height"] = 250;
  r = c.call(render_req(2, sc));
  EXPECT_EQ(error_code(r), "limit_exceeded");

  sc = small_scene();
  for (int i = 0; i < 3; ++i) sc["beams"].push_back(sc["beams"][0]);
  r = c.call(render_req(3, sc));
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/scene/beams");

  json req = render_req(4, small_scene());
  req["params"]["cameras"] = json::array();
  for (int i = 0; i < 5; ++i) req["params"]["cameras"].push_back(small_scene()["cameras"][0]);
  r = c.call(req);
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/cameras");

  sc = small_scene();
  sc["occluders"] = {{{"type", "mesh"}, {"file", "meshes/torus.obj"}}};  // 256 triangles
  r = c.call(render_req(5, sc));
  EXPECT_EQ(error_code(r), "limit_exceeded");

  // A supersampled camera renders at k times its size: 3 x 100 > max_width,
  // in the scene and as the request's output override.
  sc = small_scene();
  sc["cameras"][0]["width"] = 100;
  sc["cameras"][0]["height"] = 50;
  sc["output"] = {{"supersample", 3}};
  r = c.call(render_req(6, sc));
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/scene/output/supersample");
  sc.erase("output");
  req = render_req(7, sc);
  req["params"]["output"] = {{"supersample", 3}};
  r = c.call(req);
  EXPECT_EQ(error_code(r), "limit_exceeded");
  EXPECT_EQ(error_path(r), "/params/output/supersample");
  req["params"]["output"] = {{"supersample", 2}};  // 200 x 100: within both limits
  r = c.call(req);
  EXPECT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(frame_png(r, 0).width, 100);
  EXPECT_TRUE(s.healthy());
}

TEST(Server, InflightLimitsAnswerBusyInsteadOfQueueing) {
  ServerConfig cfg;
  cfg.max_inflight_per_connection = 2;
  cfg.max_inflight_total = 3;
  TestServer s(cfg);
  // Per connection: 6 renders sent at once; each takes milliseconds to render
  // while the next request is parsed in microseconds, so the 3rd..6th find
  // two in flight.
  Conn c(s.port());
  for (int i = 0; i < 6; ++i) c.send(render_req(i, small_scene(256)));
  int ok = 0, busy = 0;
  for (int i = 0; i < 6; ++i) {
    Reply r = c.recv();
    if (r.json["ok"]) {
      ++ok;
    } else {
      EXPECT_EQ(error_code(r), "busy");
      ++busy;
    }
  }
  EXPECT_GE(ok, 2);
  EXPECT_GE(busy, 1);
  // In total: two connections filling at once cannot exceed 3 in flight.
  Conn a(s.port()), b(s.port());
  for (int i = 0; i < 2; ++i) {
    a.send(render_req(i, small_scene(256)));
    b.send(render_req(i, small_scene(256)));
  }
  int total_ok = 0;
  for (int i = 0; i < 2; ++i) {
    total_ok += a.recv().json["ok"].get<bool>();
    total_ok += b.recv().json["ok"].get<bool>();
  }
  EXPECT_LE(total_ok, 4);
  EXPECT_GE(s.core().stats.errors("busy"), 1u);
  EXPECT_TRUE(s.healthy());
}

// A render refused because the server is full (max_inflight_total) gives
// its connection's slot back: the connection's next render, once the server
// has room, is admitted, not refused by max_inflight_per_connection forever.
TEST(Server, BusyForTheTotalLimitLeavesTheConnectionFree) {
  ServerConfig cfg;
  cfg.max_inflight_per_connection = 1;
  cfg.max_inflight_total = 1;
  TestServer s(cfg);
  Conn a(s.port()), b(s.port());
  Conn* refused = nullptr;
  // Both at once until one finds the other's render in flight (bounded).
  for (int i = 0; i < 20 && !refused; ++i) {
    a.send(render_req(i, small_scene(256)));
    b.send(render_req(i, small_scene(256)));
    const Reply ra = a.recv(), rb = b.recv();
    if (!ra.json["ok"]) refused = &a;
    if (!rb.json["ok"]) refused = &b;
  }
  ASSERT_NE(refused, nullptr) << "no render met another in flight in 20 tries";
  EXPECT_EQ(s.core().stats.errors("busy"), 1u);
  const Reply r = refused->call(render_req(100, small_scene()));
  EXPECT_TRUE(r.json["ok"]) << r.json;
}

TEST(Server, ConnectionLimitRefusesTheExtraClientOnly) {
  ServerConfig cfg;
  cfg.max_connections = 2;
  TestServer s(cfg);
  Conn a(s.port()), b(s.port());
  ASSERT_TRUE(a.call({{"id", 1}, {"method", "ping"}}).json["ok"]);
  ASSERT_TRUE(b.call({{"id", 1}, {"method", "ping"}}).json["ok"]);
  Conn extra(s.port());
  Reply r = extra.recv();
  EXPECT_EQ(error_code(r), "busy");
  EXPECT_TRUE(extra.closed_by_peer());
  EXPECT_TRUE(a.call({{"id", 2}, {"method", "ping"}}).json["ok"]);
}

TEST(Server, IdleAndSlowSendersTimeOut) {
  ServerConfig cfg;
  cfg.idle_timeout_ms = 300;
  cfg.read_timeout_ms = 300;
  TestServer s(cfg);
  Conn idle(s.port());
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  EXPECT_TRUE(idle.closed_by_peer());

  Conn slow(s.port());
  const std::string body = R"({"id": 1, "method": "ping"})";
  auto frame = encode_frame(body);
  frame.resize(kFrameHeaderSize + 5);  // header and the first bytes, then silence
  slow.send_raw(frame);
  Reply r = slow.recv();
  EXPECT_EQ(error_code(r), "timeout");
  EXPECT_TRUE(slow.closed_by_peer());
  EXPECT_TRUE(s.healthy());
}

TEST(Server, DisconnectMidRequestLeavesServerHealthy) {
  TestServer s;
  {
    Conn c(s.port());
    for (int i = 0; i < 10; ++i) c.send(render_req(i, small_scene(384)));
    // Gone before the answers: queued work must be dropped, not rendered.
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  // Wait until the server has read all ten requests and finished with them.
  auto settled = [&s] {
    const json st = s.core().stats.to_json();
    return st["requests"].value("render", 0) == 10 && s.core().renders->inflight() == 0;
  };
  while (!settled() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(s.core().renders->inflight(), 0);
  // Each 384x384 render takes tens of milliseconds, the disconnect arrives
  // within one: most of the ten were still queued and never reached the GPU.
  EXPECT_GE(s.core().renders->dropped(), 1u) << s.core().stats.to_json();
  EXPECT_TRUE(s.healthy());
  Conn c(s.port());
  EXPECT_TRUE(c.call(render_req(1, small_scene())).json["ok"]);
}

TEST(Server, EightConcurrentClientsRenderWithoutErrors) {
  TestServer s;
  std::atomic<int> errors{0}, frames{0};
  std::vector<std::thread> clients;
  for (int k = 0; k < 8; ++k) {
    clients.emplace_back([&, k] {
      try {
        Conn c(s.port());
        for (int i = 0; i < 6; ++i) {
          json sc = small_scene(48 + 8 * k);
          sc["cameras"][0]["position"] = {std::sin(i + k), 1.0, 5.0};
          const Reply r = c.call(render_req(i, sc));
          if (!r.json["ok"] || r.json["id"] != i || frame_png(r, 0).width != 48 + 8 * k) {
            ++errors;
          } else {
            ++frames;
          }
        }
      } catch (const std::exception&) {
        ++errors;
      }
    });
  }
  for (auto& t : clients) t.join();
  EXPECT_EQ(errors.load(), 0);
  EXPECT_EQ(frames.load(), 48);
}

}  // namespace
}  // namespace beamcast

namespace beamcast {
namespace {

// Cross-connection batching: three viewers of one stored scene whose requests
// arrive within the window share one multi-view render; each gets its own
// frame (pixel-identical to rendering it alone) and is told it was batched.
TEST(Server, BatchWindowMergesViewersOfOneStoredScene) {
  ServerConfig cfg;
  // Long enough that three requests sent back to back land in it even on a
  // loaded 2-core machine (they arrive within a few ms normally).
  cfg.batch_window_ms = 1500;
  TestServer s(cfg);
  Conn setup(s.port());
  ASSERT_TRUE(setup.call({{"id", 1}, {"method", "scene.put"},
                          {"params", {{"scene_id", "shared"}, {"scene", small_scene(48)}}}})
                  .json["ok"]);
  const json poses = {{{"position", {0, 1, 5}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 48}},
                      {{"position", {4, 1, 3}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 48}},
                      {{"position", {-3, 2, 4}}, {"target", {0, 0, 0}}, {"width", 48}, {"height", 48}}};
  std::vector<std::unique_ptr<Conn>> viewers;
  for (int i = 0; i < 3; ++i) viewers.push_back(std::make_unique<Conn>(s.port()));
  for (int i = 0; i < 3; ++i) {
    viewers[i]->send({{"id", i},
                      {"method", "render"},
                      {"params", {{"scene_id", "shared"}, {"cameras", json::array({poses[i]})}}}});
  }
  Renderer offline;
  Scene scene = parse_scene(small_scene(48), SceneLoadOptions{});
  for (int i = 0; i < 3; ++i) {
    const Reply r = viewers[i]->recv();
    ASSERT_TRUE(r.json["ok"]) << r.json;
    EXPECT_EQ(r.json["id"], i);
    const RenderResponse res = test::render_result(r);
    EXPECT_TRUE(res.batched);
    EXPECT_EQ(res.batch_requests, 3);
    EXPECT_EQ(res.batch_views, 3);
    ASSERT_EQ(res.frames.size(), 1u);
    ASSERT_TRUE(res.frames[0].gpu_batch);
    EXPECT_EQ(res.frames[0].gpu_batch->views, 3);  // one multi-view pass
    scene.cameras = {parse_camera(poses[i], "", SceneLimits{})};
    const auto alone = offline.render(scene);
    EXPECT_EQ(compare_levels(frame_png(r, 0), alone[0].image).max_abs, 0) << "viewer " << i;
  }
  // An inline scene is never merged, and says so.
  const Reply r = setup.call(render_req(9, small_scene(32)));
  ASSERT_TRUE(r.json["ok"]) << r.json;
  EXPECT_EQ(r.json["result"]["batched"], false);
  EXPECT_EQ(r.json["result"]["batch"]["requests"], 1);
}

TEST(Server, WithoutBatchWindowRequestsRenderAlone) {
  TestServer s;  // default: window 0
  Conn a(s.port()), b(s.port());
  ASSERT_TRUE(a.call({{"id", 1}, {"method", "scene.put"},
                      {"params", {{"scene_id", "shared"}, {"scene", small_scene(32)}}}})
                  .json["ok"]);
  const json req = {{"method", "render"}, {"params", {{"scene_id", "shared"}}}};
  json ra = req, rb = req;
  ra["id"] = 1;
  rb["id"] = 2;
  a.send(ra);
  b.send(rb);
  for (Conn* c : {&a, &b}) {
    const Reply r = c->recv();
    ASSERT_TRUE(r.json["ok"]) << r.json;
    EXPECT_EQ(r.json["result"]["batched"], false);
  }
}

}  // namespace
}  // namespace beamcast

namespace beamcast {
namespace {

// "atlas": true returns one PNG whose tiles are the frames of a plain render,
// at the documented grid positions.
TEST(Server, AtlasTilesEveryFrameInTheDocumentedGrid) {
  TestServer s;
  Conn c(s.port());
  json req = render_req(1, small_scene(24));
  req["params"]["cameras"] = {{{"rig", "orbit"}, {"count", 5}, {"width", 24}, {"height", 16}}};
  const Reply plain = c.call(req);
  ASSERT_TRUE(plain.json["ok"]) << plain.json;
  req["id"] = 2;
  req["params"]["atlas"] = true;
  const Reply r = c.call(req);
  ASSERT_TRUE(r.json["ok"]) << r.json;
  ASSERT_EQ(r.json["result"]["frames"].size(), 1u);
  const json& f = r.json["result"]["frames"][0];
  EXPECT_EQ(f["camera"], "atlas");
  EXPECT_EQ(f["atlas"]["columns"], 3);  // ceil(sqrt(5))
  EXPECT_EQ(f["atlas"]["rows"], 2);
  const Image atlas = frame_png(r, 0);
  ASSERT_EQ(atlas.width, 3 * 24);
  ASSERT_EQ(atlas.height, 2 * 16);
  const json& tiles = f["atlas"]["tiles"];
  ASSERT_EQ(tiles.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(tiles[i]["x"], (i % 3) * 24);
    EXPECT_EQ(tiles[i]["y"], (i / 3) * 16);
    EXPECT_EQ(tiles[i]["camera"], plain.json["result"]["frames"][i]["camera"]);
    const Image one = frame_png(plain, i);
    int differ = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 24 * 3; ++x)
        differ += one.rgb[y * 24 * 3 + x] !=
                  atlas.rgb[(tiles[i]["y"].get<int>() + y) * atlas.width * 3 +
                            tiles[i]["x"].get<int>() * 3 + x];
    EXPECT_EQ(differ, 0) << "tile " << i;
  }
  // The unused sixth cell is black.
  for (int y = 16; y < 32; ++y)
    for (int x = 48 * 3; x < 72 * 3; ++x) ASSERT_EQ(atlas.rgb[y * atlas.width * 3 + x], 0);
  // A bad flag is refused with its path.
  req["id"] = 3;
  req["params"]["atlas"] = "yes";
  const Reply bad = c.call(req);
  EXPECT_EQ(error_code(bad), "wrong_type");
  EXPECT_EQ(error_path(bad), "/params/atlas");
}

}  // namespace
}  // namespace beamcast
