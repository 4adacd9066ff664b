// The render scheduler (PROTOCOL.md, "Scheduling" and "Streaming") with the
// GL-free renderer (fake_renderer.hpp): jobs are rendered in slices of
// max_batch_views cameras, interactive frames overtake batch work between
// slices, connections of one class take turns, a disconnected client's job
// stops within one slice, and a streamed render sends each slice's frames as
// it finishes. The renderer holds a render (hold_after) so the tests queue
// work behind it and then read the order of render calls: no timing.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "client/client.hpp"
#include "protocol/scene_json.hpp"
#include "render/image.hpp"
#include "tests/server/fake_renderer.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

// Waits (polling) until `cond` holds; false after 20 s (a hung scheduler).
template <class F>
bool eventually(F cond) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!cond()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

json camera(const std::string& name, int size = 8) {
  return {{"name", name}, {"position", {0, 1, 5}}, {"target", {0, 0, 0}},
          {"width", size}, {"height", size}};
}

// A render of the tiny scene with cameras named prefix0..prefix<n-1>.
json render_req(int id, const std::string& prefix, int n, json extra = json::object()) {
  json cams = json::array();
  for (int i = 0; i < n; ++i) cams.push_back(camera(prefix + std::to_string(i)));
  json params = {{"scene", test::tiny_scene(8)}, {"cameras", cams}};
  params.update(extra);
  return {{"id", id}, {"method", "render"}, {"params", params}};
}

std::vector<std::string> names(std::initializer_list<const char*> l) {
  return {l.begin(), l.end()};
}

TEST(Scheduling, AJobRendersInSlicesAndInteractiveFramesGoBetweenThem) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  test::Conn batch(s.port(), 30), preview(s.port(), 30);
  control->hold_after(0);  // the first slice waits in the renderer
  batch.send(render_req(1, "b", 12));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  // While the batch's first slice renders, its other two wait and a preview
  // frame (quality auto) arrives.
  preview.send(render_req(2, "i", 1, {{"quality", "auto"}}));
  ASSERT_TRUE(eventually([&] { return s.core().renders->queued(WorkClass::kInteractive) == 1; }));
  EXPECT_EQ(s.core().renders->queued(WorkClass::kBatch), 1);
  control->release();

  const test::Reply p = preview.recv();
  ASSERT_TRUE(p.json.value("ok", false)) << p.json;
  const test::Reply b = batch.recv();
  ASSERT_TRUE(b.json.value("ok", false)) << b.json;
  // FIFO would have rendered the 12 cameras first; slices of 4 (the default
  // max_batch_views) let the interactive frame in after the first.
  const auto log = control->call_log();
  ASSERT_EQ(log.size(), 4u);
  EXPECT_EQ(log[0], names({"b0", "b1", "b2", "b3"}));
  EXPECT_EQ(log[1], names({"i0"}));
  EXPECT_EQ(log[2], names({"b4", "b5", "b6", "b7"}));
  EXPECT_EQ(log[3], names({"b8", "b9", "b10", "b11"}));
  // The batch's response is unchanged by the slicing: 12 frames in camera
  // order, each image intact, GPU batches numbered over the whole job.
  const RenderResponse r = test::render_result(b);
  ASSERT_EQ(r.frames.size(), 12u);
  for (std::size_t i = 0; i < 12; ++i) {
    EXPECT_EQ(r.frames[i].camera, "b" + std::to_string(i));
    EXPECT_EQ(r.frames[i].index, i);
    ASSERT_TRUE(r.frames[i].gpu_batch);
    EXPECT_EQ(r.frames[i].gpu_batch->index, static_cast<int>(i / 4));
    const Image img = decode_png(test::frame_bytes(b, i));
    EXPECT_EQ(img.width, 8);
  }
  EXPECT_FALSE(r.stream);
}

TEST(Scheduling, BatchWorkSubmittedWhileAPreviewIsActiveRendersOneCameraPerSlice) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  // A window far longer than the test: "active" cannot lapse on a slow machine.
  s.core().renders->set_interactive_window(std::chrono::hours(1));
  test::Conn c(s.port(), 30);
  ASSERT_TRUE(c.call(render_req(1, "b", 3)).json.value("ok", false));  // no preview yet
  ASSERT_TRUE(c.call(render_req(2, "i", 1, {{"quality", "auto"}})).json.value("ok", false));
  ASSERT_TRUE(c.call(render_req(3, "c", 3)).json.value("ok", false));
  const auto log = control->call_log();
  ASSERT_EQ(log.size(), 5u);
  EXPECT_EQ(log[0], names({"b0", "b1", "b2"}));
  EXPECT_EQ(log[1], names({"i0"}));
  EXPECT_EQ(log[2], names({"c0"}));
  EXPECT_EQ(log[3], names({"c1"}));
  EXPECT_EQ(log[4], names({"c2"}));
}

TEST(Scheduling, FourPipelinedConnectionsTakeTurns) {
#if defined(BEAMCAST_ASAN)
  // Turns go by measured render time, equal within 5 ms (kTurnQuantumMs):
  // one fake render preempted for longer puts its connection a turn behind.
  // In the Debug + ASan build beside a compile that happened in 5 of 10 runs
  // (clang-14) and 1 of 10 (g++), never on an idle machine or in the release
  // build; the scheduler's code runs under the sanitizers in this file's
  // other tests.
  GTEST_SKIP() << "turn order by measured time: the release build checks it";
#endif
  auto control = std::make_shared<test::FakeRendererControl>();
  ServerConfig cfg;  // defaults: 16 in flight per connection
  cfg.max_inflight_total = 65;  // the four connections' 64 and the blocker's
  test::LocalServer s(cfg, test::fake_renderer_factory(control));
  constexpr int kConns = 4, kEach = 16;
  std::vector<std::unique_ptr<test::Conn>> conns;
  for (int c = 0; c < kConns; ++c) conns.push_back(std::make_unique<test::Conn>(s.port(), 30));
  // A fifth connection's render holds the renderer while the four queue
  // (held, it is charged the time it waits: turns go by render time used).
  test::Conn blocker(s.port(), 30);
  control->hold_after(0);
  blocker.send(render_req(0, "b_", 1));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  // Connection 0 pipelines its whole queue first, then the others: FIFO would
  // serve all of connection 0 before anyone else.
  for (int c = 0; c < kConns; ++c) {
    for (int j = 0; j < kEach; ++j) {
      conns[c]->send(render_req(j, "c" + std::to_string(c) + "_", 1));
    }
  }
  ASSERT_TRUE(eventually([&] { return s.core().renders->queued() == kConns * kEach; }));
  control->release();
  ASSERT_TRUE(blocker.recv().json.value("ok", false));
  for (auto& c : conns) {
    for (int j = 0; j < kEach; ++j) {
      const test::Reply r = c->recv();
      ASSERT_TRUE(r.json.value("ok", false)) << r.json;
    }
  }
  const auto log = control->call_log();
  ASSERT_EQ(log.size(), static_cast<std::size_t>(kConns * kEach + 1));
  // After the held first render, turns go round the connections: in every
  // prefix of the render order each connection has had its share within one
  // render, so their throughputs agree to 1/16 (the issue asks for 20%).
  std::map<char, int> count;
  for (std::size_t k = 1; k < log.size(); ++k) {
    ASSERT_EQ(log[k].size(), 1u);
    ++count[log[k][0][1]];
    int lo = kEach, hi = 0;
    for (char c = '0'; c < '0' + kConns; ++c) {
      lo = std::min(lo, count[c]);
      hi = std::max(hi, count[c]);
    }
    ASSERT_LE(hi - lo, 1) << "render " << k << " (" << log[k][0] << ")";
  }
}

// Turns go by the render time each connection has used, measured, not by
// request or estimate: connection A's renders take 300 ms each in the
// renderer, B's next to nothing, both with the same estimated cost. After
// A's first render B's whole queue runs before A's second (by request or by
// estimate they would alternate).
TEST(Scheduling, TurnsGoByMeasuredRenderTime) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  control->slow_renders("a_", 300);
  test::Conn blocker(s.port(), 30), a(s.port(), 30), b(s.port(), 30);
  control->hold_after(0);
  blocker.send(render_req(0, "x_", 1));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  constexpr int kB = 6;
  for (int j = 0; j < 2; ++j) a.send(render_req(j, "a_", 1));
  ASSERT_TRUE(eventually([&] { return s.core().renders->queued() == 2; }));  // A's turn first
  for (int j = 0; j < kB; ++j) b.send(render_req(j, "b_", 1));
  ASSERT_TRUE(eventually([&] { return s.core().renders->queued() == 2 + kB; }));
  control->release();
  ASSERT_TRUE(blocker.recv().json.value("ok", false));
  for (int j = 0; j < 2; ++j) ASSERT_TRUE(a.recv().json.value("ok", false));
  for (int j = 0; j < kB; ++j) ASSERT_TRUE(b.recv().json.value("ok", false));
  std::string order;  // the connection of each render call after the blocker's
  for (const auto& call : control->call_log()) order += call.at(0).at(0);
  EXPECT_EQ(order, "xa" + std::string(kB, 'b') + "a");
}

// The encode hold (RenderService::set_hold_batch_encodes): two render
// workers, an interactive frame held in one renderer while the other renders
// a batch frame. The batch frame's encode (an 8x8 PNG, microseconds) must not
// start until the interactive render returns: its job is not answered while
// the interactive one is in the renderer, and is once it is out. With the hold
// off the same batch job is answered while the interactive frame is still
// held. The 300 ms wait only bounds how long "not answered" is watched; a
// broken hold answers within microseconds of the render.
RenderJob hold_job(const std::shared_ptr<const Scene>& scene, WorkClass cls, std::uint64_t client,
                   std::atomic<int>* answered) {
  RenderJob job;
  job.scene = scene;
  job.cameras = {scene->cameras.front()};
  job.cameras[0].name = cls == WorkClass::kInteractive ? "i" : "b";
  job.client_alive = std::make_shared<std::atomic<bool>>(true);
  job.arrived = std::chrono::steady_clock::now();
  job.work_class = cls;
  job.client = client;
  job.done = [answered](RenderOutcome&& o) {
    EXPECT_FALSE(o.error.has_value());
    EXPECT_EQ(o.pngs.size(), 1u);
    answered->fetch_add(1);
  };
  return job;
}

void check_encode_hold(bool hold) {
  auto control = std::make_shared<test::FakeRendererControl>();
  RenderService service(test::fake_renderer_factory(control), 2, 1, PngSettings{}, 16);
  service.wait_ready();
  service.set_hold_batch_encodes(hold);
  const auto scene = std::make_shared<const Scene>(parse_scene(test::tiny_scene(8), {}));
  std::atomic<int> interactive{0}, batch{0};
  control->hold_call(1);
  ASSERT_TRUE(service.submit(hold_job(scene, WorkClass::kInteractive, 1, &interactive)));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  ASSERT_TRUE(service.submit(hold_job(scene, WorkClass::kBatch, 2, &batch)));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 2; }));
  if (hold) {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(batch.load(), 0) << "a batch encode ran while an interactive frame rendered";
  } else {
    EXPECT_TRUE(eventually([&] { return batch.load() == 1; }));
  }
  EXPECT_EQ(interactive.load(), 0);
  control->release_call(1);
  EXPECT_TRUE(eventually([&] { return interactive.load() == 1 && batch.load() == 1; }));
  service.stop();
}

TEST(Scheduling, BatchEncodesWaitWhileAnInteractiveFrameRenders) { check_encode_hold(true); }

TEST(Scheduling, WithoutTheHoldBatchEncodesRunBesideAnInteractiveRender) {
  check_encode_hold(false);
}

// Turns inside a slice (RenderService::set_turn, protocol/turns.hpp): one
// worker renders connection A's costly slice, which runs until the test ends it
// (the fake renderer's slow render, a turn point every 1 ms). A cheap render
// of connection B, submitted meanwhile, is answered while A's slice is
// still in the renderer; a costly one of connection C (estimated over
// kTurnSliceMaxCost) is not rendered in a turn and waits for the worker.
// Without turns B waits for A's whole slice (here: until the 20 s poll fails).
TEST(Scheduling, ACheapRenderRunsInATurnInsideALongSlice) {
  auto control = std::make_shared<test::FakeRendererControl>();
  RenderService service(test::fake_renderer_factory(control), 1, 1, PngSettings{}, 16);
  service.wait_ready();
  service.set_turn(std::chrono::milliseconds(5));
  const auto scene = std::make_shared<const Scene>(parse_scene(test::tiny_scene(8), {}));
  control->slow_renders("a_", 60000);
  const auto job = [&](const char* name, std::uint64_t client, double cost,
                       std::atomic<int>* answered) {
    RenderJob j;
    j.scene = scene;
    j.cameras = {scene->cameras.front()};
    j.cameras[0].name = name;
    j.client_alive = std::make_shared<std::atomic<bool>>(true);
    j.arrived = std::chrono::steady_clock::now();
    j.client = client;
    j.cost = cost;
    j.done = [answered](RenderOutcome&& o) {
      EXPECT_FALSE(o.error.has_value()) << o.error->message;
      answered->fetch_add(1);
    };
    return j;
  };
  std::atomic<int> a{0}, b{0}, c{0};
  ASSERT_TRUE(service.submit(job("a_0", 1, 10.0 * kTurnSliceMaxCost, &a)));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  ASSERT_TRUE(service.submit(job("c_0", 3, 10.0 * kTurnSliceMaxCost, &c)));
  ASSERT_TRUE(service.submit(job("b_0", 2, 10.0, &b)));
  const bool b_in_turn = eventually([&] { return b.load() == 1; });
  const int a_then = a.load();
  const auto log_then = control->call_log();
  control->end_slow_renders();
  EXPECT_TRUE(b_in_turn) << "the cheap render waited for the long slice";
  EXPECT_EQ(a_then, 0);
  for (const auto& call : log_then) EXPECT_NE(call.at(0), "c_0") << "a costly slice ran in a turn";
  EXPECT_TRUE(eventually([&] { return a.load() == 1 && c.load() == 1; }));
  EXPECT_GE(service.turns_taken(), 1u);
  service.stop();
}

// A cheap slice that runs long (a loaded machine) gives no turns: the
// second renderer is made only beside costly work. A's slice is estimated
// cheap and held 300 ms; B's render waits for it (answered after A's).
TEST(Scheduling, ACheapSliceGivesNoTurns) {
  auto control = std::make_shared<test::FakeRendererControl>();
  RenderService service(test::fake_renderer_factory(control), 1, 1, PngSettings{}, 16);
  service.wait_ready();
  service.set_turn(std::chrono::milliseconds(5));
  const auto scene = std::make_shared<const Scene>(parse_scene(test::tiny_scene(8), {}));
  control->slow_renders("a_", 300);
  std::atomic<int> order{0}, a_at{0}, b_at{0};
  const auto job = [&](const char* name, std::uint64_t client, std::atomic<int>* at) {
    RenderJob j;
    j.scene = scene;
    j.cameras = {scene->cameras.front()};
    j.cameras[0].name = name;
    j.client_alive = std::make_shared<std::atomic<bool>>(true);
    j.arrived = std::chrono::steady_clock::now();
    j.client = client;
    j.cost = 10.0;
    j.done = [&order, at](RenderOutcome&&) { at->store(++order); };
    return j;
  };
  ASSERT_TRUE(service.submit(job("a_0", 1, &a_at)));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  ASSERT_TRUE(service.submit(job("b_0", 2, &b_at)));
  ASSERT_TRUE(eventually([&] { return a_at.load() > 0 && b_at.load() > 0; }));
  EXPECT_LT(a_at.load(), b_at.load());
  EXPECT_EQ(service.turns_taken(), 0u);
  service.stop();
}

// A slice whose frames the worker would finish after submitting the next
// (a renderer that overlaps them, as the GL one does) is finished first when
// the next slice is costly (estimated over kTurnSliceMaxCost): B's cheap
// render is answered while A's costly one renders (until the test ends it).
// Before, B's frames waited in the renderer for all of A's slice.
TEST(Scheduling, ACheapSlicesFramesDoNotWaitForTheCostlySliceAfterIt) {
  auto control = std::make_shared<test::FakeRendererControl>();
  control->overlap = true;
  RenderService service(test::fake_renderer_factory(control), 1, 1, PngSettings{}, 16);
  service.wait_ready();
  const auto scene = std::make_shared<const Scene>(parse_scene(test::tiny_scene(8), {}));
  control->slow_renders("a_", 60000);
  const auto job = [&](const char* name, std::uint64_t client, double cost,
                       std::atomic<int>* answered) {
    RenderJob j;
    j.scene = scene;
    j.cameras = {scene->cameras.front()};
    j.cameras[0].name = name;
    j.client_alive = std::make_shared<std::atomic<bool>>(true);
    j.arrived = std::chrono::steady_clock::now();
    j.client = client;
    j.cost = cost;
    j.done = [answered](RenderOutcome&& o) {
      EXPECT_FALSE(o.error.has_value()) << o.error->message;
      answered->fetch_add(1);
    };
    return j;
  };
  std::atomic<int> x{0}, a{0}, b{0};
  control->hold_call(1);  // the worker holds X while B and A queue
  ASSERT_TRUE(service.submit(job("x_0", 3, 10.0, &x)));
  ASSERT_TRUE(eventually([&] { return control->call_count() == 1; }));
  ASSERT_TRUE(service.submit(job("b_0", 2, 10.0, &b)));
  ASSERT_TRUE(service.submit(job("a_0", 1, 10.0 * kTurnSliceMaxCost, &a)));
  control->release_call(1);
  const bool b_answered = eventually([&] { return b.load() == 1; });
  const int a_then = a.load();
  control->end_slow_renders();
  EXPECT_TRUE(b_answered) << "the cheap slice's frames waited for the costly slice";
  EXPECT_EQ(a_then, 0);
  EXPECT_TRUE(eventually([&] { return a.load() == 1 && x.load() == 1; }));
  const auto log = control->call_log();
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[1].at(0), "b_0");  // cheap first (fair turns), then the costly one
  service.stop();
}

TEST(Scheduling, ADisconnectedClientsJobStopsWithinOneSlice) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  {
    test::Conn c(s.port(), 30);
    control->hold_after(1);  // slice 0 renders, slice 1 waits in the renderer
    c.send(render_req(1, "x", 32));  // 8 slices of 4
    ASSERT_TRUE(eventually([&] { return control->call_count() == 2; }));
    c.close();
  }
  // The server has seen the close (the session object itself lives on until
  // its render completes).
  ASSERT_TRUE(eventually([&] { return s.core().stats.connections_gone() == 1; }));
  control->release();
  ASSERT_TRUE(eventually([&] { return s.core().renders->inflight() == 0; }));
  // The slice in the renderer when the client left finishes; the other six
  // never reach it.
  EXPECT_EQ(control->call_count(), 2u);
  EXPECT_EQ(s.core().renders->slices_dropped(), 6u);
  EXPECT_EQ(s.core().renders->cancelled(), 1u);
  EXPECT_EQ(s.core().renders->dropped(), 0u);  // it had reached the GPU
  // The next client is served as usual.
  test::Conn next(s.port(), 30);
  const test::Reply r = next.call(render_req(2, "y", 1));
  EXPECT_TRUE(r.json.value("ok", false)) << r.json;
}

TEST(Scheduling, AStreamedRenderSendsEachSliceAsItFinishes) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  test::Conn c(s.port(), 30);
  control->hold_after(1);  // slice 0 renders; slice 1 waits in the renderer
  c.send(render_req(7, "s", 14, {{"stream", true}}));
  // Part 0 arrives while the rest is still held in the renderer.
  const test::Reply first = c.recv();
  ASSERT_TRUE(first.json.value("ok", false)) << first.json;
  EXPECT_EQ(control->call_count(), 2u);
  std::vector<test::Reply> parts = {first};
  control->release();
  for (int k = 1; k < 4; ++k) parts.push_back(c.recv());  // 14 cameras: 4 + 4 + 4 + 2

  std::vector<int> seen(14, 0);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const test::Reply& p = parts[k];
    ASSERT_TRUE(p.json.value("ok", false)) << p.json;
    EXPECT_EQ(p.json["id"], 7);
    const RenderResponse r = test::render_result(p);
    ASSERT_TRUE(r.stream);
    EXPECT_EQ(r.stream->part, static_cast<int>(k));
    EXPECT_EQ(r.stream->last, k == 3);
    EXPECT_EQ(r.stream->frames, 14u);
    ASSERT_EQ(r.frames.size(), k == 3 ? 2u : 4u);
    for (std::size_t f = 0; f < r.frames.size(); ++f) {
      // Frames in slice order, each naming its camera; attachments point into
      // this message's own binary part.
      EXPECT_EQ(r.frames[f].index, 4 * k + f);
      EXPECT_EQ(r.frames[f].camera, "s" + std::to_string(4 * k + f));
      ++seen[r.frames[f].index];
      const Image img = decode_png(test::frame_bytes(p, f));
      EXPECT_EQ(img.width, 8);
    }
  }
  for (int n : seen) EXPECT_EQ(n, 1);
}

TEST(Scheduling, StreamParamsAreChecked) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  test::Conn c(s.port(), 30);
  test::Reply r = c.call(render_req(1, "a", 2, {{"stream", true}, {"atlas", true}}));
  EXPECT_EQ(r.json["error"]["code"], "conflicting_fields") << r.json;
  EXPECT_EQ(r.json["error"]["path"], "/params/stream");
  r = c.call(render_req(2, "a", 2, {{"stream", "yes"}}));
  EXPECT_EQ(r.json["error"]["code"], "wrong_type") << r.json;
  EXPECT_EQ(r.json["error"]["path"], "/params/stream");
  // A one-slice streamed render is one message, marked last.
  r = c.call(render_req(3, "a", 1, {{"stream", true}}));
  ASSERT_TRUE(r.json.value("ok", false)) << r.json;
  const RenderResponse rr = test::render_result(r);
  ASSERT_TRUE(rr.stream);
  EXPECT_EQ(rr.stream->part, 0);
  EXPECT_TRUE(rr.stream->last);
  // hello offers it.
  r = c.call({{"id", 4}, {"method", "hello"}});
  EXPECT_EQ(r.json["result"]["capabilities"]["stream"], true) << r.json;
}

TEST(Scheduling, TheClientAssemblesAStreamedRender) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  client::Client cl;
  cl.connect("127.0.0.1", s.port());
  client::RenderRequest req;
  req.scene = test::tiny_scene(8);
  req.cameras = json::array();
  for (int i = 0; i < 10; ++i) req.cameras.push_back(camera("k" + std::to_string(i)));
  req.stream = true;
  std::vector<int> part_sizes;
  req.on_part = [&](int part, const std::vector<client::RenderedFrame>& frames) {
    EXPECT_EQ(part, static_cast<int>(part_sizes.size()));
    part_sizes.push_back(static_cast<int>(frames.size()));
  };
  const client::RenderResult r = cl.render(req);
  ASSERT_TRUE(r.ok) << r.error.message;
  EXPECT_EQ(r.parts, 3);
  EXPECT_EQ(part_sizes, (std::vector<int>{4, 4, 2}));
  ASSERT_EQ(r.frames.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(r.frames[i].index, i);
    EXPECT_EQ(r.frames[i].camera, "k" + std::to_string(i));
    EXPECT_FALSE(r.frames[i].png.empty());
  }
  EXPECT_LE(r.first_part_ms, r.e2e_ms);
}

TEST(Scheduling, MetricsShowQueueDepthAndWaitByClass) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  test::Conn c(s.port(), 30);
  ASSERT_TRUE(c.call(render_req(1, "m", 1)).json.value("ok", false));
  ASSERT_TRUE(c.call(render_req(2, "m", 1, {{"quality", "auto"}})).json.value("ok", false));
  const test::Reply st =
      c.call({{"id", 3}, {"method", "stats"}, {"params", {{"format", "prometheus"}}}});
  const std::string text = st.json["result"]["text"];
  for (const char* line :
       {"beamcast_class_wait_seconds_count{class=\"batch\"} 1",
        "beamcast_class_wait_seconds_count{class=\"interactive\"} 1",
        "beamcast_class_queue_depth{class=\"interactive\"} 0",
        "beamcast_class_queue_depth{class=\"batch\"} 0", "beamcast_slices_dropped_total 0",
        "beamcast_renders_cancelled_total 0"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
  const test::Reply js = c.call({{"id", 4}, {"method", "stats"}});
  EXPECT_EQ(js.json["result"]["queue_depth_by_class"]["batch"], 0) << js.json;
}

}  // namespace
}  // namespace beamcast
