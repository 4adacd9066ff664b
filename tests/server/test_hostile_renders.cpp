// Issue 43, items 1-3 and "SIGTERM always wins": the exact small requests
// that killed, hung or bloated the server at 1e19280, over TCP and through
// scene.put + render by id; a render past max_render_ms; and the real
// beamcast-server binary obeying SIGTERM while a costly render runs.
#include <gtest/gtest.h>
#include <malloc.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>
#include <thread>

#include "gi/gi_scene.hpp"
#include "gi/photon_map.hpp"
#include "protocol/scene_json.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast::test {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// Item 1: a quad light with a subnormal edge (1e-310) over a plane.
constexpr const char* kAbortRequest =
    R"({"id":"abort","method":"render","params":{"scene":{"lights":[{"type":"quad","corner":[0,1,0],"edge_u":[1e-310,0,0],"edge_v":[0,0,1],"power":1}],"occluders":[{"type":"plane","point":[0,0,0],"normal":[0,1,0]}],"gi":{"photons":1,"caustic_photons":0},"cameras":[{"width":8,"height":8}]}}})";
// Item 2: a sphere region of sigma_s 1 in fog of 1e-300 (delta tracking's
// majorant 1 against an extinction of 1e-300 everywhere outside it).
constexpr const char* kHangRequest =
    R"({"id":"hang","method":"render","params":{"scene":{"lights":[{"type":"point","position":[0,0,0],"power":1}],"medium":{"sigma_s":1e-300},"media":[{"type":"sphere","center":[0,0,0],"radius":1,"sigma_s":1}],"gi":{"photons":1,"caustic_photons":0},"cameras":[{"width":8,"height":8}]}}})";
// Item 3: a point light inside a closed sphere filled with fog: every
// photon stores up to max_depth 64 scattering events.
constexpr const char* kFogRequest =
    R"({"id":"fog","method":"render","params":{"scene":{"lights":[{"type":"point","position":[0,0,0],"power":1}],"occluders":[{"type":"sphere","center":[0,0,0],"radius":3}],"medium":{"sigma_s":2},"gi":{"photons":100000,"caustic_photons":0,"max_depth":64},"cameras":[{"width":8,"height":8}]}}})";

json small_render(const std::string& id) {
  return {{"id", id}, {"method", "render"}, {"params", {{"scene", tiny_scene(16)}}}};
}

// The server is alive and renders: a ping and a small render both answer ok.
void expect_alive(Conn& c) {
  const Reply ping = c.call({{"id", "ping"}, {"method", "ping"}});
  EXPECT_TRUE(ping.json.value("ok", false)) << ping.json.dump();
  const Reply r = c.call(small_render("small"));
  EXPECT_TRUE(r.json.value("ok", false)) << r.json.dump();
}

// The request's scene stored with scene.put, then rendered by id: the reply
// to the put, or (if stored) to the render.
Reply put_then_render(Conn& c, const std::string& request_text, const std::string& id) {
  json scene = json::parse(request_text)["params"]["scene"];
  json cams = scene["cameras"];
  const Reply put = c.call({{"id", id + "-put"},
                            {"method", "scene.put"},
                            {"params", {{"scene_id", id}, {"scene", scene}}}});
  if (!put.json.value("ok", false)) return put;
  return c.call({{"id", id + "-render"},
                 {"method", "render"},
                 {"params", {{"scene_id", id}, {"cameras", cams}}}});
}

double rss_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1 << 20);
}

// Item 1 (and item 7's numbers): refused with the field's path, never an abort.
TEST(HostileRenders, SubnormalQuadEdgeIsRefusedNotAnAbort) {
  LocalServer server;
  Conn c(server.port(), 30);
  c.send_text(kAbortRequest);
  const Reply r = c.recv();
  EXPECT_EQ(r.json["error"]["code"], "out_of_range") << r.json.dump();
  EXPECT_EQ(r.json["error"]["path"], "/params/scene/lights/0/edge_u/0") << r.json.dump();
  const Reply put = put_then_render(c, kAbortRequest, "abort");
  EXPECT_EQ(put.json["error"]["code"], "out_of_range") << put.json.dump();
  EXPECT_EQ(put.json["error"]["path"], "/params/scene/lights/0/edge_u/0") << put.json.dump();

  // Normal but tiny numbers whose products underflowed: each refused at a
  // field, or rendered; none may reach Embree as NaN.
  const json base = json::parse(kAbortRequest);
  for (const auto& [u, v] : {std::pair{json{1e-300, 0, 0}, json{0, 0, 1}},
                             std::pair{json{1e-150, 0, 0}, json{0, 0, 1e-150}},
                             std::pair{json{1, 0, 0}, json{1, 1e-300, 0}},
                             std::pair{json{1e12, 0, 0}, json{0, 0, 1e12}}}) {
    json req = base;
    req["params"]["scene"]["lights"][0]["edge_u"] = u;
    req["params"]["scene"]["lights"][0]["edge_v"] = v;
    const Reply a = c.call(req);
    if (!a.json.value("ok", false)) {
      EXPECT_NE(a.json["error"]["code"], "internal") << a.json.dump();
      EXPECT_TRUE(a.json["error"]["path"].get<std::string>().starts_with("/params/scene/lights/0"))
          << a.json.dump();
    }
  }
  // A quaternion of length 1e-200 is a rotation like any other.
  json rot = json::parse(kAbortRequest);
  rot["params"]["scene"]["cameras"][0]["rotation"] = {1e-200, 0, 0, 0};
  rot["params"]["scene"]["lights"][0]["edge_u"] = {1, 0, 0};
  const Reply q = c.call(rot);
  EXPECT_TRUE(q.json.value("ok", false)) << q.json.dump();
  // gi.radius 1e308 is over the upper bound, and the message says so.
  json big = rot;
  big["params"]["scene"]["gi"]["radius"] = 1e308;
  const Reply b = c.call(big);
  EXPECT_EQ(b.json["error"]["path"], "/params/scene/gi/radius") << b.json.dump();
  EXPECT_NE(b.json["error"]["message"].get<std::string>().find("1e+12"), std::string::npos)
      << b.json.dump();
  expect_alive(c);
}

// Item 2: answered (a bounded render), and the worker is free afterwards.
TEST(HostileRenders, DeltaTrackingRequestsAnswer) {
  LocalServer server;
  Conn c(server.port(), 20);  // at 1e19280 no answer ever came: recv times out
  const auto t0 = Clock::now();
  c.send_text(kHangRequest);
  const Reply r = c.recv();
  EXPECT_TRUE(r.json.value("ok", false)) << r.json.dump();
  const Reply s = put_then_render(c, kHangRequest, "hang");
  EXPECT_TRUE(s.json.value("ok", false)) << s.json.dump();
  // Legal values: a region of sigma_s 1e6 inside fog of 0.1 with the light
  // outside it (ran past 20 s: a majorant of 1e6 in fog of 0.1).
  json dense = json::parse(kHangRequest);
  dense["params"]["scene"]["lights"][0]["position"] = {0, 3, 0};
  dense["params"]["scene"]["medium"]["sigma_s"] = 0.1;
  dense["params"]["scene"]["media"][0]["sigma_s"] = 1e6;
  dense["params"]["scene"]["gi"]["photons"] = 2000;
  const Reply d = c.call(dense);
  EXPECT_TRUE(d.json.value("ok", false)) << d.json.dump();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 15.0);
  expect_alive(c);
}

// Item 3: the stored events are counted; past max_photon_events the render
// is refused with the limit's name, and the memory is given back.
TEST(HostileRenders, FogPhotonEventsAreBounded) {
  ServerConfig cfg;
  cfg.scene_limits.max_photon_events = 400000;  // 21 MB of events; the request would store 6.4 M
  LocalServer server(cfg);
  Conn c(server.port(), 30);
  expect_alive(c);  // the renderer's own memory (context, shaders) before the baseline
  malloc_trim(0);
  const double before = rss_mib();
  c.send_text(kFogRequest);
  const Reply r = c.recv();
  ASSERT_TRUE(r.json.contains("error")) << "rendered: the events were not bounded";
  EXPECT_EQ(r.json["error"]["code"], "limit_exceeded") << r.json.dump();
  EXPECT_NE(r.json["error"]["message"].get<std::string>().find("max_photon_events = 400000"),
            std::string::npos)
      << r.json.dump();
  EXPECT_EQ(r.json["error"]["path"], "/params/scene/gi/photons") << r.json.dump();
  const Reply s = put_then_render(c, kFogRequest, "fog");
  ASSERT_TRUE(s.json.contains("error")) << s.json.dump();
  EXPECT_EQ(s.json["error"]["code"], "limit_exceeded") << s.json.dump();
  EXPECT_EQ(s.json["error"]["path"], "/params/scene_id") << s.json.dump();
  expect_alive(c);
  malloc_trim(0);
  const double after = rss_mib();
  // 50 MiB: the issue's budget for RSS after a burst; the cap alone holds
  // the events to 21 MB, and they are freed when tracing stops. Not under
  // AddressSanitizer: its quarantine keeps freed memory (up to 256 MB).
#if !defined(BEAMCAST_ASAN)
  EXPECT_LT(after - before, 50.0) << "RSS " << before << " MiB -> " << after << " MiB";
#endif
  std::printf("fog request: RSS %.1f MiB before, %.1f MiB after\n", before, after);
}

// Issue 43, "memory that is bounded and returns": what a large legal render
// leaves in the renderer's caches (here the photon maps of 400 000 photons in
// the Cornell box with their splat disks, under the cache's 256 MiB budget,
// so kept) is given back once the server has been
// idle for the idle-release delay (kIdleReleaseMs, 500 ms here to keep the
// test short), and the next render of the scene still answers.
TEST(HostileRenders, CachedPhotonMapsAreGivenBackOnceIdle) {
  LocalServer server;
  server.core().renders->set_idle_release(std::chrono::milliseconds(500));
  Conn c(server.port(), 60);
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/examples/cornell_box.json");
  json scene = json::parse(in);
  scene["gi"] = {{"photons", 2000}, {"caustic_photons", 0}};
  scene["cameras"][0]["width"] = 32;
  scene["cameras"][0]["height"] = 32;
  // The same scene with few photons first: the renderer's own memory (the
  // lit passes' shader variants, ~45 MiB on llvmpipe) is in the baseline.
  const Reply warm = c.call({{"id", "warm"}, {"method", "render"}, {"params", {{"scene", scene}}}});
  ASSERT_TRUE(warm.json.value("ok", false)) << warm.json.dump().substr(0, 300);
  std::this_thread::sleep_for(std::chrono::milliseconds(900));  // its idle release
  malloc_trim(0);
  const double before = rss_mib();
  scene["gi"]["photons"] = 400000;
  const json request = {{"id", "lit"}, {"method", "render"}, {"params", {{"scene", scene}}}};
  const auto t0 = Clock::now();
  const Reply r = c.call(request);
  ASSERT_TRUE(r.json.value("ok", false)) << r.json.dump().substr(0, 300);
  const double held = rss_mib();
  // Idle: the release comes 0.5 s after the render (polled every 100 ms,
  // for up to 4 s).
  for (int i = 0; i < 40 && server.core().renders->idle_releases() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const double after = rss_mib();
  std::printf("lit render (%.2f s): RSS %.1f MiB before, %.1f right after, %.1f once idle\n",
              std::chrono::duration<double>(Clock::now() - t0).count(), before, held, after);
  EXPECT_GE(server.core().renders->idle_releases(), 2u);
#if !defined(BEAMCAST_ASAN)
  // Right after the render the cache holds the maps (measured +35 MiB here,
  // +54 in CI, and still +35 after 4 s without the release); once idle the
  // cache keeps at most 16 MiB of maps (these are larger: evicted), so the
  // release gives back what they held: measured 30 MiB both here and in CI.
  // What stays above the baseline is not the cache's and differs between
  // machines (+6 MiB here, +24 in CI: llvmpipe's code for the shader
  // variants this render compiled, allocator pages), so it is held to the
  // issue's budget (50 MiB) and the release's share is checked on its own:
  // 20 MiB, two thirds of the measured return and far above the ~0 returned
  // without it. Not under AddressSanitizer: its quarantine keeps freed
  // memory resident.
  EXPECT_GT(held - before, 25.0) << "the render held too little to tell";
  EXPECT_GT(held - after, 20.0) << "RSS " << held << " MiB -> " << after
                                << " MiB: the idle release gave back too little";
  EXPECT_LT(after - before, 50.0) << "RSS " << before << " MiB -> " << after << " MiB once idle";
#endif
  const Reply again = c.call(request);  // traced again: answers as before
  EXPECT_TRUE(again.json.value("ok", false)) << again.json.dump().substr(0, 300);
}

// A scene whose photon tracing takes seconds (legal: 4e6 photons in fog in
// a closed sphere, up to 64 events each).
json costly_request(const std::string& id) {
  json req = json::parse(kFogRequest);
  req["id"] = id;
  req["params"]["scene"]["gi"]["photons"] = 4000000;
  return req;
}

// A render past max_render_ms: deadline_exceeded, the worker freed, the
// connection kept.
TEST(HostileRenders, DeadlineExceededFreesTheWorker) {
  ServerConfig cfg;
  cfg.max_render_ms = 1500;  // a small render (shaders compiled) takes well under it
  // Admitted whatever its estimate: the deadline is what is under test.
  cfg.max_request_cost = std::numeric_limits<std::int64_t>::max();
  LocalServer server(cfg);
  Conn c(server.port(), 30);
  expect_alive(c);
  const auto t0 = Clock::now();
  const Reply r = c.call(costly_request("costly"));
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(r.json["error"]["code"], "deadline_exceeded") << r.json.dump();
  // The deadline plus one check interval (64 photons), the answer and the
  // context rebuilt after it, with room for a loaded CI machine and the
  // sanitizers' slowdown: without the deadline the render runs for minutes.
  EXPECT_LT(s, 1.5 + 6.0) << s << " s";
  expect_alive(c);
}

// Fair shares (PROTOCOL.md, "Scheduling"): a costly legal render's photon
// tracing (tens of seconds: 4e6 photons in closed fog until
// max_photon_events) runs off the render worker, so a small render beside it
// is answered while it traces; and once its client has gone the trace stops
// at its next check (every 64 photons) instead of running on.
TEST(HostileRenders, ASmallRenderPassesACostlyTraceThatStopsWhenItsClientGoes) {
  ServerConfig cfg;
  // Admitted whatever its estimate: the scheduling is what is under test.
  cfg.max_request_cost = std::numeric_limits<std::int64_t>::max();
  LocalServer server(cfg);
  Conn small(server.port(), 60);
  expect_alive(small);  // shaders compiled
  {
    Conn costly(server.port(), 60);
    costly.send(costly_request("costly"));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // tracing by now
    const Reply r = small.call(small_render("beside"));
    EXPECT_TRUE(r.json.value("ok", false)) << r.json.dump();
    // Answered while the costly render is still in flight (not after it).
    EXPECT_EQ(server.core().renders->inflight(), 1);
  }
  // The costly client has gone: its trace stops well within the bound (the
  // check interval is milliseconds; the whole trace takes tens of seconds,
  // and minutes under the sanitizers).
  const auto t0 = Clock::now();
  while (server.core().renders->inflight() > 0 && Clock::now() - t0 < std::chrono::seconds(15)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(server.core().renders->inflight(), 0)
      << "the trace ran on after its client had gone";
  expect_alive(small);
}

// The server traces photon maps off the render worker and hands them to the
// renderer (FrameOptions::photon_maps): the frames are bit for bit those of
// a renderer that traces them itself, for surface photons, caustics and
// media (the maps do not depend on the thread count; traced here on one).
TEST(HostileRenders, MapsTracedOffTheRendererGiveTheSameFrames) {
  for (const char* name : {"cornell_caustic", "ground_fog"}) {
    SCOPED_TRACE(name);
    Scene scene = load_scene_file(std::filesystem::path(BEAMCAST_SOURCE_DIR) / "examples" /
                                      (std::string(name) + ".json"),
                                  {});
    scene.cameras.resize(1);
    scene.cameras[0].width = scene.cameras[0].height = 32;
    scene.gi.photons = scene.gi.caustic_photons = 20000;  // a cheap test (the maps' rule is the same)
    FrameOptions traced_before;
    traced_before.photon_maps = std::make_shared<const PhotonMaps>(
        trace_photons(scene, GiScene(scene), PhotonTraceOptions{1}));
    Renderer itself, given;
    ASSERT_TRUE(itself.needs_photon_trace(scene, {}));
    ASSERT_FALSE(given.needs_photon_trace(scene, traced_before));
    const std::vector<FrameResult> a = itself.render(scene, scene.cameras);
    const std::vector<FrameResult> b = given.render(scene, scene.cameras, traced_before);
    ASSERT_EQ(a.size(), 1u);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_GT(b[0].photons, 0);
    EXPECT_TRUE(a[0].image.rgb == b[0].image.rgb);
    // Cached now: neither traces again.
    EXPECT_FALSE(itself.needs_photon_trace(scene, {}));
    EXPECT_FALSE(given.needs_photon_trace(scene, {}));
    // The server's path (Renderer::submit, then finish) takes the handed
    // maps too: marked by a trace time of 1e6 ms, which the frame reports
    // (a trace of these 2e4 photons takes well under a second).
    auto marked = std::make_shared<PhotonMaps>(*traced_before.photon_maps);
    marked->trace_ms = 1.0e6;
    FrameOptions handed;
    handed.photon_maps = marked;
    Renderer submitted;
    const std::vector<FrameResult> c =
        submitted.finish(submitted.submit(scene, scene.cameras, handed));
    ASSERT_EQ(c.size(), 1u);
    EXPECT_GE(c[0].photon_trace_ms, marked->trace_ms) << "the maps handed over were traced again";
    EXPECT_TRUE(a[0].image.rgb == c[0].image.rgb);
  }
}

// SIGTERM while a costly render runs: the process exits within the drain
// deadline (plus the answer and the process's own teardown).
TEST(ServerProcess, SigtermEndsACostlyRender) {
  int out[2];
  ASSERT_EQ(pipe(out), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    execl(BEAMCAST_SERVER_BIN, BEAMCAST_SERVER_BIN, "--port", "0", "--http-port", "-1",
          "--no-demo", "--quiet-requests", "--drain-timeout-ms", "1000",
          // Admitted whatever its estimate: SIGTERM during the render is under test.
          "--max-request-cost", "9223372036854775807", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(out[1]);
  // First line: "beamcast-server listening on 127.0.0.1:PORT".
  std::string line;
  char ch = 0;
  while (read(out[0], &ch, 1) == 1 && ch != '\n') line += ch;
  const auto colon = line.rfind(':');
  ASSERT_NE(colon, std::string::npos) << "server printed: " << line;
  const auto port = static_cast<unsigned short>(std::stoi(line.substr(colon + 1)));
  {
    Conn c(port, 30);
    c.send(costly_request("costly"));
    std::this_thread::sleep_for(std::chrono::milliseconds(700));  // tracing by now
    const auto t0 = Clock::now();
    ASSERT_EQ(kill(pid, SIGTERM), 0);
    int status = 0;
    pid_t done = 0;
    while ((done = waitpid(pid, &status, WNOHANG)) == 0 &&
           Clock::now() - t0 < std::chrono::seconds(8)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (done == 0) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
    }
    EXPECT_EQ(done, pid) << "still running " << s << " s after SIGTERM";
    // The drain deadline (1 s), then the cancelled render's answer and the
    // teardown; the watchdog would end it at 3 s with status 2.
#if defined(BEAMCAST_ASAN)
    // Debug + sanitizers: the teardown (and LeakSanitizer's pass at exit) can
    // outlast the watchdog's 2 s, which then ends the process with status 2:
    // SIGTERM obeyed either way.
    EXPECT_LT(s, 8.0) << s << " s";
    EXPECT_TRUE(WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 2))
        << "status " << status;
#else
    EXPECT_LT(s, 3.0) << s << " s";
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
#endif
  }
  close(out[0]);
}

}  // namespace
}  // namespace beamcast::test
