// beamcast_client against a scripted peer on a loopback socket (no real
// server): id matching with out-of-order responses, frame decoding from
// attachments and base64, server errors as values, and transport failures
// (timeout, close, bad magic, refused) as std::runtime_error; ResilientClient's
// retries on a new connection, re-puts, budget and refusals.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "client/client.hpp"
#include "client/resilient_client.hpp"
#include "protocol/framing.hpp"

namespace beamcast::client {
namespace {

using nlohmann::json;

// Listens on 127.0.0.1:<ephemeral>, accepts one connection per script, one
// after the other, and runs each script on its connection.
class FakePeer {
 public:
  explicit FakePeer(std::function<void(int fd)> script)
      : FakePeer(std::vector<std::function<void(int fd)>>{std::move(script)}) {}
  explicit FakePeer(std::vector<std::function<void(int fd)>> scripts) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof addr;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), len) != 0 ||
        ::listen(listen_fd_, 1) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
      throw std::runtime_error("FakePeer: cannot listen");
    }
    port_ = ntohs(addr.sin_port);
    thread_ = std::thread([this, scripts = std::move(scripts)] {
      for (const auto& script : scripts) {
        const int fd = ::accept(listen_fd_, nullptr, nullptr);
        if (fd < 0) return;
        script(fd);
        ::close(fd);
      }
    });
  }
  ~FakePeer() {
    ::shutdown(listen_fd_, SHUT_RDWR);  // unblocks accept if nobody connected
    thread_.join();
    ::close(listen_fd_);
  }
  std::uint16_t port() const { return port_; }

 private:
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::thread thread_;
};

bool read_exact(int fd, std::uint8_t* p, std::size_t n) {
  while (n > 0) {
    const ssize_t got = ::recv(fd, p, n, 0);
    if (got <= 0) return false;
    p += got;
    n -= static_cast<std::size_t>(got);
  }
  return true;
}

json read_request(int fd) {
  std::uint8_t header[kFrameHeaderSize];
  FrameHeader h;
  if (!read_exact(fd, header, sizeof header) ||
      parse_frame_header(std::span<const std::uint8_t, kFrameHeaderSize>(header), 1 << 20, &h) !=
          HeaderStatus::kOk) {
    return nullptr;
  }
  std::string body(h.body_length(), '\0');
  if (!read_exact(fd, reinterpret_cast<std::uint8_t*>(body.data()), body.size())) return nullptr;
  return json::parse(body.substr(0, h.json_length));
}

void write_raw(int fd, const std::vector<std::uint8_t>& bytes) {
  ASSERT_EQ(::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL),
            static_cast<ssize_t>(bytes.size()));
}

void reply(int fd, const json& response, const std::vector<std::uint8_t>& binary = {}) {
  write_raw(fd, encode_frame(response.dump(), binary));
}

RenderRequest stored(const std::string& scene_id) {
  RenderRequest r;
  r.scene_id = scene_id;
  return r;
}
RenderRequest inline_scene(const json& scene) {
  RenderRequest r;
  r.scene = scene;
  return r;
}

TEST(ClientLoopback, CallMatchesItsIdAndKeepsTheOthers) {
  FakePeer peer([](int fd) {
    const json a = read_request(fd);
    const json b = read_request(fd);
    EXPECT_EQ(a["method"], "ping");
    EXPECT_EQ(b["method"], "stats");
    EXPECT_NE(a["id"], b["id"]);  // auto-incremented
    reply(fd, {{"id", a["id"]}, {"ok", true}, {"result", {{"echo", a["params"]}}}});
    reply(fd, {{"id", b["id"]}, {"ok", true}, {"result", {{"frames", 3}}}});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  const json ping_id = c.send({{"method", "ping"}, {"params", {{"x", 1}}}});
  const Response stats = c.stats();  // the ping's answer arrives first and is kept
  ASSERT_TRUE(stats.ok);
  EXPECT_EQ(stats.result()["frames"], 3);
  const Response ping = c.receive_for(ping_id);
  ASSERT_TRUE(ping.ok);
  EXPECT_EQ(ping.id, ping_id);
  EXPECT_EQ(ping.result()["echo"]["x"], 1);
}

TEST(ClientLoopback, RenderDecodesAttachmentsAndBase64) {
  const std::vector<std::uint8_t> png_a = {0x89, 'P', 'N', 'G', 1, 2, 3};
  const std::vector<std::uint8_t> png_b = {0x89, 'P', 'N', 'G', 0, 255};
  FakePeer peer([&](int fd) {
    const json req = read_request(fd);
    EXPECT_EQ(req["params"]["scene_id"], "demo");
    EXPECT_EQ(req["params"]["encoding"], "binary");
    std::vector<std::uint8_t> binary = {9, 9};  // attachments need not start at 0
    binary.insert(binary.end(), png_a.begin(), png_a.end());
    const json frames = json::array({{{"camera", "view"},
                                      {"index", 0},
                                      {"width", 4},
                                      {"height", 2},
                                      {"format", "png"},
                                      {"attachment", {{"offset", 2}, {"length", png_a.size()}}},
                                      {"gpu_ms", 1.5},
                                      {"pass_ms", {{"beams", 1.5}}}},
                                     {{"camera", "camera_1"},
                                      {"index", 1},
                                      {"width", 8},
                                      {"height", 8},
                                      {"data_base64", base64_encode(png_b)},
                                      {"encode_ms", 0.5}}});
    reply(fd,
          {{"id", req["id"]},
           {"ok", true},
           {"result",
            {{"passes", {"beams", "tonemap"}},
             {"frames", frames},
             {"batched", false},
             {"batch", {{"requests", 1}, {"views", 2}}},
             {"timings",
              {{"queue_ms", 0.1},
               {"render_ms", 1.0},
               {"readback_ms", 0.2},
               {"encode_ms", 0.5},
               {"server_ms", 2.5}}}}}},
          binary);
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  const RenderResult r = c.render(stored("demo"));
  ASSERT_TRUE(r.ok) << r.error.message;
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_EQ(r.frames[0].camera, "view");
  EXPECT_EQ(r.frames[0].width, 4);
  EXPECT_EQ(r.frames[0].png, png_a);
  EXPECT_EQ(r.frames[0].timings["gpu_ms"], 1.5);
  EXPECT_TRUE(r.frames[0].timings.contains("pass_ms"));
  EXPECT_EQ(r.frames[1].png, png_b);
  EXPECT_EQ(r.passes, json({"beams", "tonemap"}));
  EXPECT_DOUBLE_EQ(r.server_ms, 2.5);
  EXPECT_GE(r.e2e_ms, 0.0);
  EXPECT_DOUBLE_EQ(r.network_ms, r.e2e_ms - r.server_ms);
}

TEST(ClientLoopback, ServerErrorIsReturnedNotThrown) {
  FakePeer peer([](int fd) {
    const json req = read_request(fd);
    reply(fd, {{"id", req["id"]},
               {"ok", false},
               {"error",
                {{"code", "invalid_value"},
                 {"message", "radius must be > 0"},
                 {"path", "/params/scene/beams/0/radius"}}}});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  const RenderResult r = c.render(inline_scene(json::parse(R"({"cameras": [{}]})")));
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error.code, "invalid_value");
  EXPECT_EQ(r.error.path, "/params/scene/beams/0/radius");
}

TEST(ClientLoopback, NullIdErrorReachesTheWaitingCall) {
  FakePeer peer([](int fd) {
    read_request(fd);
    reply(fd, {{"id", nullptr},
               {"ok", false},
               {"error", {{"code", "busy"}, {"message", "too many connections"}, {"path", ""}}}});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  const Response r = c.ping();
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error.code, "busy");
}

// Runs `fn`, expecting std::runtime_error whose message contains `needle`.
void expect_transport_error(const std::function<void()>& fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one mentioning '" << needle << "'";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(ClientLoopback, AttachmentOutsideTheBinaryPartThrows) {
  FakePeer peer([](int fd) {
    const json req = read_request(fd);
    const json frame = {{"camera", "v"},
                        {"index", 0},
                        {"width", 1},
                        {"height", 1},
                        {"attachment", {{"offset", 1}, {"length", 4}}}};
    const json timings = {{"queue_ms", 0}, {"render_ms", 0}, {"readback_ms", 0},
                          {"encode_ms", 0}, {"server_ms", 0}};
    reply(fd,
          {{"id", req["id"]},
           {"ok", true},
           {"result",
            {{"passes", json::array()},
             {"frames", json::array({frame})},
             {"batched", false},
             {"batch", {{"requests", 1}, {"views", 1}}},
             {"timings", timings}}}},
          {1, 2, 3, 4});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  expect_transport_error([&] { c.render(stored("demo")); }, "outside the 4-byte binary section");
}

TEST(ClientLoopback, MalformedRenderResultNamesTheField) {
  FakePeer peer([](int fd) {
    const json req = read_request(fd);
    reply(fd, {{"id", req["id"]}, {"ok", true}, {"result", {{"frames", json::array()}}}});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  expect_transport_error([&] { c.render(stored("demo")); }, "/result/passes: required field");
}

TEST(ClientLoopback, ReceiveTimesOut) {
  FakePeer peer([](int fd) {
    read_request(fd);
    read_request(fd);  // holds the connection, never answers, until the client closes
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  c.set_receive_timeout(std::chrono::milliseconds(200));
  expect_transport_error([&] { c.ping(); }, "timed out");
  EXPECT_FALSE(c.is_open());
}

TEST(ClientLoopback, ClosedConnectionThrows) {
  FakePeer peer([](int fd) { read_request(fd); });
  Client c;
  c.connect("127.0.0.1", peer.port());
  expect_transport_error([&] { c.ping(); }, "closed the connection");
}

TEST(ClientLoopback, BadMagicThrows) {
  FakePeer peer([](int fd) {
    read_request(fd);
    write_raw(fd, {'H', 'T', 'T', 'P', '/', '1', '.', '1', ' ', '4', '0', '0'});
  });
  Client c;
  c.connect("127.0.0.1", peer.port());
  expect_transport_error([&] { c.ping(); }, "BCP1");
}

TEST(ClientLoopback, RefusedConnectThrows) {
  std::uint16_t port = 0;
  {
    FakePeer peer([](int) {});  // an ephemeral port that is closed once the peer is gone
    port = peer.port();
    Client c;
    c.connect("127.0.0.1", port);  // lets the peer's accept return
  }
  Client c;
  expect_transport_error([&] { c.connect("127.0.0.1", port); }, "127.0.0.1:");
  expect_transport_error([&] { c.ping(); }, "not connected");
}

// --- ResilientClient ---

// A render result with one base64 frame, enough for Client::render.
json one_frame_result(const json& id) {
  const std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G'};
  return {{"id", id},
          {"ok", true},
          {"result",
           {{"passes", {"beams"}},
            {"frames", json::array({{{"camera", "c"},
                                     {"index", 0},
                                     {"width", 1},
                                     {"height", 1},
                                     {"data_base64", base64_encode(png)}}})},
            {"batched", false},
            {"batch", {{"requests", 1}, {"views", 1}}},
            {"timings",
             {{"queue_ms", 0.0},
              {"render_ms", 1.0},
              {"readback_ms", 0.0},
              {"encode_ms", 0.0},
              {"server_ms", 1.0}}}}}};
}

ResilientOptions fast_retries(int attempts = 5) {
  ResilientOptions o;
  o.policy.max_attempts = attempts;
  o.policy.base = std::chrono::milliseconds(1);  // tests wait milliseconds, not seconds
  o.policy.cap = std::chrono::milliseconds(5);
  o.receive_timeout = std::chrono::milliseconds(2000);
  return o;
}

TEST(ResilientClient, DroppedConnectionIsRetriedOnANewOne) {
  FakePeer peer({[](int fd) { read_request(fd); },  // takes the ping, closes unanswered
                 [](int fd) {
                   const json req = read_request(fd);
                   EXPECT_EQ(req["method"], "ping");
                   reply(fd, {{"id", req["id"]}, {"ok", true}, {"result", json::object()}});
                 }});
  ResilientClient c({"127.0.0.1", peer.port()}, std::make_shared<RetryBudget>(), fast_retries());
  EXPECT_TRUE(c.ping().ok);
  EXPECT_EQ(c.stats().requests, 1u);
  EXPECT_EQ(c.stats().retries, 1u);
  EXPECT_EQ(c.stats().connections, 2u);
}

TEST(ResilientClient, UnknownScenePutsTheSceneAgain) {
  const json scene = {{"beams", json::array()}};
  FakePeer peer({[](int fd) {
                   const json put = read_request(fd);
                   reply(fd, {{"id", put["id"]}, {"ok", true}, {"result", json::object()}});
                   read_request(fd);  // the render: the connection drops (its server died)
                 },
                 [&](int fd) {  // another server, without the scene
                   const json render = read_request(fd);
                   reply(fd, {{"id", render["id"]},
                              {"ok", false},
                              {"error", {{"code", "unknown_scene"}, {"message", "no scene s"}}}});
                   const json put = read_request(fd);
                   EXPECT_EQ(put["method"], "scene.put");
                   EXPECT_EQ(put["params"]["scene"], scene);
                   reply(fd, {{"id", put["id"]}, {"ok", true}, {"result", json::object()}});
                   const json again = read_request(fd);
                   EXPECT_EQ(again["params"]["scene_id"], "s");
                   reply(fd, one_frame_result(again["id"]));
                 }});
  ResilientClient c({"127.0.0.1", peer.port()}, std::make_shared<RetryBudget>(), fast_retries());
  c.scene_put("s", scene);
  const RenderResult r = c.render(stored("s"));
  ASSERT_TRUE(r.ok) << r.error.message;
  EXPECT_EQ(r.frames.size(), 1u);
  EXPECT_EQ(c.stats().retries, 1u);
  EXPECT_EQ(c.stats().reputs, 1u);
}

TEST(ResilientClient, AnEmptyBudgetStopsRetries) {
  FakePeer peer([](int fd) { read_request(fd); });
  // No burst: one request earns 0.1 of a retry, not enough for one.
  auto budget = std::make_shared<RetryBudget>(0.1, 0.0);
  ResilientClient c({"127.0.0.1", peer.port()}, budget, fast_retries());
  expect_transport_error([&] { c.ping(); }, "the retry budget is spent");
  EXPECT_EQ(c.stats().retries, 0u);
  EXPECT_EQ(budget->refused(), 1u);
}

TEST(ResilientClient, GivesUpAfterItsAttemptsNamingTheEndpoint) {
  std::uint16_t port = 0;
  {
    FakePeer peer([](int) {});
    port = peer.port();
    Client probe;
    probe.connect("127.0.0.1", port);
  }  // nothing listens there now: every connect is refused
  ResilientClient c({"127.0.0.1", port}, std::make_shared<RetryBudget>(), fast_retries(3));
  expect_transport_error([&] { c.ping(); }, "gave up after 3 tries");
  expect_transport_error([&] { c.ping(); }, "127.0.0.1:" + std::to_string(port));
  EXPECT_EQ(c.stats().retries, 4u);  // two per request
}

TEST(ResilientClient, AWrongTokenIsRefusedNotRetried) {
  FakePeer peer([](int fd) {
    const json hello = read_request(fd);
    EXPECT_EQ(hello["params"]["token"], "wrong");
    reply(fd, {{"id", hello["id"]},
               {"ok", false},
               {"error", {{"code", "unauthorized"}, {"message", "bad token"}, {"path", "/params/token"}}}});
  });
  ResilientOptions o = fast_retries();
  o.token = "wrong";
  ResilientClient c({"127.0.0.1", peer.port()}, std::make_shared<RetryBudget>(), o);
  try {
    c.ping();
    ADD_FAILURE() << "a refused hello must throw";
  } catch (const RequestRefused& e) {
    EXPECT_EQ(e.error().code, "unauthorized");
    EXPECT_NE(std::string(e.what()).find("refused hello"), std::string::npos) << e.what();
  }
  EXPECT_EQ(c.stats().connections, 1u);
  EXPECT_EQ(c.stats().retries, 0u);
}

TEST(ResilientClient, ATimeoutIsReportedNotRetried) {
  FakePeer peer([](int fd) {
    read_request(fd);
    read_request(fd);  // never answers; returns when the client closes
  });
  ResilientOptions o = fast_retries();
  o.receive_timeout = std::chrono::milliseconds(200);
  ResilientClient c({"127.0.0.1", peer.port()}, std::make_shared<RetryBudget>(), o);
  try {
    c.ping();
    ADD_FAILURE() << "a silent server must time out";
  } catch (const TransportTimeout& e) {
    EXPECT_NE(std::string(e.what()).find("timed out (not retried)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(c.stats().connections, 1u);
  EXPECT_EQ(c.stats().retries, 0u);
}

TEST(RetryBudget, RetriesAreATenthOfRequestsPlusTheBurst) {
  RetryBudget b(0.1, 10.0);
  int granted = 0;
  for (int i = 0; i < 1000; ++i) {
    b.on_request();
    if (b.try_spend()) ++granted;
  }
  // Every request asks for a retry: the burst of 10, then one per ten requests.
  EXPECT_GE(granted, 109);
  EXPECT_LE(granted, 110);
}

TEST(RetryBudget, BackoffIsFullJitterUnderTheCap) {
  RetryPolicy p;
  p.base = std::chrono::milliseconds(20);
  p.cap = std::chrono::milliseconds(1000);
  std::mt19937_64 rng(7);
  for (int attempt = 0; attempt < 12; ++attempt) {
    const double top_us = std::min(1e6, 20e3 * std::ldexp(1.0, attempt));
    double hi = 0;
    for (int i = 0; i < 200; ++i) {
      const auto d = backoff_delay(p, attempt, rng).count();
      EXPECT_GE(d, 0);
      EXPECT_LE(d, top_us);
      hi = std::max(hi, static_cast<double>(d));
    }
    // Uniform over [0, top]: 200 draws all below half the top has odds 2^-200.
    EXPECT_GT(hi, 0.5 * top_us) << "attempt " << attempt;
  }
}


}  // namespace
}  // namespace beamcast::client
