// Access control (server/auth.hpp, docs/security.md): bind policy, the token
// gate in front of every request, constant-time comparison. The token tests
// bind 0.0.0.0 (not loopback, so the policy applies) and connect to 127.0.0.1,
// which reaches a wildcard bind and works without any network.
#include <gtest/gtest.h>

#include <stdexcept>

#include "protocol/framing.hpp"
#include "server/auth.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::Conn;
using test::LocalServer;

std::string code_of(const test::Reply& r) {
  return r.json.value("ok", true) ? "" : r.json.at("error").at("code").get<std::string>();
}

TEST(Access, LoopbackAddressesAreRecognized) {
  for (const char* a : {"127.0.0.1", "127.0.0.2", "127.255.0.1", "::1", "::ffff:127.0.0.1"}) {
    EXPECT_TRUE(is_loopback_address(a)) << a;
  }
  for (const char* a : {"0.0.0.0", "::", "10.0.0.1", "192.168.1.2", "::ffff:10.0.0.1"}) {
    EXPECT_FALSE(is_loopback_address(a)) << a;
  }
  EXPECT_THROW(is_loopback_address("localhost"), std::invalid_argument);
}

TEST(Access, NonLoopbackBindWithoutTokenIsRefusedUnlessInsecure) {
  ServerConfig c;
  c.bind = "0.0.0.0";
  EXPECT_THROW(check_bind_policy(c), std::invalid_argument);
  try {
    check_bind_policy(c);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--token"), std::string::npos) << e.what();
  }
  c.token = "secret";
  EXPECT_NO_THROW(check_bind_policy(c));
  c.token.clear();
  c.insecure_no_token = true;
  EXPECT_NO_THROW(check_bind_policy(c));
  c = ServerConfig{};  // 127.0.0.1 by default: open to local processes
  EXPECT_NO_THROW(check_bind_policy(c));
}

TEST(Access, TokenComparison) {
  EXPECT_TRUE(token_matches("s3cret-token", "s3cret-token"));
  EXPECT_FALSE(token_matches("s3cret-tokem", "s3cret-token"));
  EXPECT_FALSE(token_matches("s3cret-token-", "s3cret-token"));  // longer
  EXPECT_FALSE(token_matches("s3cret", "s3cret-token"));         // prefix
  EXPECT_FALSE(token_matches("", "s3cret-token"));
  EXPECT_FALSE(token_matches("", ""));  // auth off is decided by the caller, never a match
  // A repeated prefix must not alias the expected token (the loop wraps the presented one).
  EXPECT_FALSE(token_matches("ab", "abab"));
}

TEST(Access, ServerOnNonLoopbackBindRefusesRequestsWithoutTheToken) {
  ServerConfig c;
  c.bind = "0.0.0.0";
  c.token = "correct horse battery staple";
  LocalServer s(c);
  Conn conn(s.port(), 30);
  // Anything before hello: refused, the connection stays usable.
  auto r = conn.call({{"id", 1}, {"method", "render"}, {"params", {{"scene", test::tiny_scene()}}}});
  EXPECT_EQ(code_of(r), "unauthorized");
  EXPECT_EQ(r.json.at("id"), 1);
  r = conn.call({{"id", 2}, {"method", "ping"}});
  EXPECT_EQ(code_of(r), "unauthorized");
  // hello without a token, and with a wrong one.
  r = conn.call({{"id", 3}, {"method", "hello"}, {"params", {{"protocol", 1}}}});
  EXPECT_EQ(code_of(r), "unauthorized");
  EXPECT_EQ(r.json.at("error").at("path"), "/params/token");
  r = conn.call({{"id", 4}, {"method", "hello"}, {"params", {{"token", "correct horse"}}}});
  EXPECT_EQ(code_of(r), "unauthorized");
  r = conn.call({{"id", 5}, {"method", "stats"}});
  EXPECT_EQ(code_of(r), "unauthorized");
  // The right token opens this connection only.
  r = conn.call({{"id", 6}, {"method", "hello"}, {"params", {{"token", c.token}}}});
  EXPECT_EQ(code_of(r), "") << r.json.dump();
  r = conn.call({{"id", 7}, {"method", "render"}, {"params", {{"scene", test::tiny_scene()}}}});
  EXPECT_EQ(code_of(r), "") << r.json.dump();
  EXPECT_FALSE(r.binary.empty());
  Conn other(s.port(), 30);
  EXPECT_EQ(code_of(other.call({{"id", 8}, {"method", "ping"}})), "unauthorized");
  EXPECT_EQ(s.core().stats.errors("unauthorized"), 6u);
}

TEST(Access, HttpDataRoutesNeedTheBearerToken) {
  ServerConfig c;
  EXPECT_TRUE(http_request_authorized(c, "/api/scenes", ""));  // no token configured
  c.token = "tok-123";
  EXPECT_FALSE(http_request_authorized(c, "/api/scenes", ""));
  EXPECT_FALSE(http_request_authorized(c, "/api/scenes/demo", "Bearer tok-12"));
  EXPECT_FALSE(http_request_authorized(c, "/metrics", "Basic tok-123"));
  EXPECT_TRUE(http_request_authorized(c, "/api/scenes", "Bearer tok-123"));
  EXPECT_TRUE(http_request_authorized(c, "/metrics", "Bearer tok-123"));
  // The page's static files and /health carry no data.
  EXPECT_TRUE(http_request_authorized(c, "/", ""));
  EXPECT_TRUE(http_request_authorized(c, "/health", ""));
}

TEST(Access, LoopbackServerWithoutTokenNeedsNoHello) {
  LocalServer s;  // 127.0.0.1, no token
  Conn conn(s.port(), 30);
  EXPECT_EQ(code_of(conn.call({{"id", 1}, {"method", "ping"}})), "");
}

TEST(Access, InvalidUtf8InARequestGetsBadJsonAndTheServerLives) {
  // Regression for the fuzz_request finding (docs/fuzzing.md): the parser's
  // message quoted the invalid bytes and the response failed to serialize.
  LocalServer s;
  Conn conn(s.port(), 30);
  conn.send_text("{\"id\":4,\"method\":\"ping\",\"params\":{\"k\x9c\xdd\":1}}");
  const auto r = conn.recv();
  EXPECT_EQ(code_of(r), "bad_json");
  Conn again(s.port(), 30);
  EXPECT_EQ(code_of(again.call({{"id", 1}, {"method", "ping"}})), "");
}

}  // namespace
}  // namespace beamcast
