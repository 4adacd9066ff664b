// Overload behaviour that the load tool measures (docs/performance.md,
// "Capacity and overload"): a client that does not read its frames is cut off
// at the write deadline while another client on the same server carries on.
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::Conn;
using Clock = std::chrono::steady_clock;

TEST(Overload, SlowReaderIsCutOffWithoutAffectingOthers) {
  ServerConfig cfg;
  cfg.write_timeout_ms = 500;
  cfg.max_write_queue_bytes = 128 * 1024;
  test::LocalServer s(cfg);

  std::atomic<bool> slow_done{false};
  std::atomic<int> good_ok{0}, good_bad{0};
  std::thread good([&] {
    Conn c(s.port(), 60);
    // Keeps rendering while the slow reader is being cut off, and a little after.
    for (int i = 0; i < 200 && (i < 10 || !slow_done.load()); ++i) {
      const auto r = c.call({{"id", i}, {"method", "render"}, {"params", {{"scene", test::tiny_scene(64)}}}});
      (r.json.value("ok", false) && r.json["id"] == i && !r.binary.empty() ? good_ok : good_bad)++;
    }
  });

  Conn slow(s.port(), 60);
  const int small = 4096;  // a tiny receive window: the server's writes stall at once
  setsockopt(slow.native_handle(), SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  // Big answers: four 768x768 16-bit frames of a sphere filling the view (smooth
  // gradients compress poorly at 16 bits), megabytes per answer, so the kernel's
  // socket buffers fill after a few answers whatever their autotuned size.
  json big = {{"id", 0}, {"method", "render"}, {"params", {{"scene", test::tiny_scene(768)}}}};
  big["params"]["scene"]["output"] = {{"bit_depth", 16}};
  auto& cams = big["params"]["scene"]["cameras"];
  cams[0]["position"] = {0, 0, 2.2};
  cams[0]["fov_y"] = 70;
  for (int k = 1; k < 4; ++k) {
    json cam = cams[0];
    cam["name"] = "v" + std::to_string(k);
    cam["position"] = {0.1 * k, 0, 2.2};
    cams.push_back(cam);
  }
  cams[0]["name"] = "v0";
  // Ask until the server gives up on us (bounded: 40 s). Requests are small,
  // so these sends do not block even after the server stops reading.
  const auto deadline = Clock::now() + std::chrono::seconds(40);
  for (int i = 0; s.core().stats.errors("write_timeout") == 0 && Clock::now() < deadline; ++i) {
    if (i < 40) {
      big["id"] = i;
      slow.send(big);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  slow_done = true;
  good.join();
  EXPECT_GE(s.core().stats.errors("write_timeout"), 1u);
  // The slow reader's connection is closed: reading what is left ends in EOF/reset.
  bool eof = false;
  for (int i = 0; i < 100 && !eof; ++i) {
    try {
      slow.recv();
    } catch (const std::exception&) {
      eof = true;
    }
  }
  EXPECT_TRUE(eof);
  EXPECT_EQ(good_bad.load(), 0);
  EXPECT_GE(good_ok.load(), 10);
  Conn after(s.port(), 30);
  EXPECT_TRUE(after.call({{"id", 1}, {"method", "ping"}}).json.value("ok", false));
}

}  // namespace
}  // namespace beamcast
