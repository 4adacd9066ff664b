// GET /metrics and GET /health on the HTTP listener, and the same documents
// through the TCP `stats` method (params.format).
#include <gtest/gtest.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include <string>

#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

// One HTTP/1.1 GET with Connection: close; returns the whole raw response.
std::string http_get(unsigned short port, const std::string& path) {
  boost::asio::io_context io;
  boost::asio::ip::tcp::socket s(io);
  s.connect({boost::asio::ip::make_address("127.0.0.1"), port});
  const std::string req = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  boost::asio::write(s, boost::asio::buffer(req));
  std::string out;
  boost::system::error_code ec;
  boost::asio::read(s, boost::asio::dynamic_buffer(out), ec);  // to EOF
  return out;
}

TEST(MetricsHttp, PrometheusAndHealthAfterARender) {
  ServerConfig c;
  c.http_port = 0;
  test::LocalServer s(c);
  test::Conn conn(s.port(), 60);
  ASSERT_TRUE(conn.call({{"id", 1}, {"method", "render"}, {"params", {{"scene", test::tiny_scene()}}}})
                  .json.value("ok", false));
  ASSERT_FALSE(conn.call({{"id", 2}, {"method", "nope"}}).json.value("ok", true));

  const std::string m = http_get(s.http_port(), "/metrics");
  EXPECT_NE(m.find("200"), std::string::npos) << m.substr(0, 200);
  EXPECT_NE(m.find("text/plain; version=0.0.4"), std::string::npos);
  EXPECT_NE(m.find("beamcast_requests_total{method=\"render\",outcome=\"ok\"} 1\n"), std::string::npos) << m;
  EXPECT_NE(m.find("beamcast_requests_total{method=\"(unknown)\",outcome=\"error\"} 1\n"), std::string::npos);
  EXPECT_NE(m.find("beamcast_errors_total{code=\"unknown_method\"} 1\n"), std::string::npos);
  EXPECT_NE(m.find("beamcast_stage_seconds_count{stage=\"render\"} 1\n"), std::string::npos);
  EXPECT_NE(m.find("beamcast_frames_total 1\n"), std::string::npos);

  const std::string h = http_get(s.http_port(), "/health");
  EXPECT_NE(h.find("200"), std::string::npos);
  EXPECT_NE(h.find("\"status\":\"ok\""), std::string::npos) << h;

  // The same over TCP.
  auto r = conn.call({{"id", 3}, {"method", "stats"}, {"params", {{"format", "prometheus"}}}});
  ASSERT_TRUE(r.json.value("ok", false)) << r.json;
  EXPECT_NE(r.json["result"]["text"].get<std::string>().find("beamcast_frames_total 1\n"),
            std::string::npos);
  r = conn.call({{"id", 4}, {"method", "stats"}, {"params", {{"format", "health"}}}});
  EXPECT_EQ(r.json["result"]["status"], "ok");
  r = conn.call({{"id", 5}, {"method", "stats"}, {"params", {{"format", 7}}}});
  EXPECT_EQ(r.json["error"]["code"], "invalid_value");
  EXPECT_EQ(r.json["error"]["path"], "/params/format");
}

}  // namespace
}  // namespace beamcast
