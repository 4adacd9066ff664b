// Pure helpers the client uses: base64 (protocol/base64.hpp; checked against
// RFC 4648 vectors and by round trips over many lengths and byte values) and
// HOST:PORT parsing.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "client/client.hpp"

namespace beamcast::client {
namespace {

std::vector<std::uint8_t> bytes(std::string_view s) { return {s.begin(), s.end()}; }

TEST(Base64, Rfc4648Vectors) {
  // RFC 4648 section 10: every padding case.
  const std::pair<const char*, const char*> vectors[] = {
      {"", ""},
      {"f", "Zg=="},
      {"fo", "Zm8="},
      {"foo", "Zm9v"},
      {"foob", "Zm9vYg=="},
      {"fooba", "Zm9vYmE="},
      {"foobar", "Zm9vYmFy"},
  };
  for (const auto& [plain, encoded] : vectors) {
    EXPECT_EQ(base64_encode(bytes(plain)), encoded) << plain;
    EXPECT_EQ(base64_decode(encoded), bytes(plain)) << encoded;
  }
}

TEST(Base64, AllByteValuesAndTheLastTwoLetters) {
  // 0xfb 0xff 0xbf uses '+' and '/', the characters URL-safe base64 replaces.
  EXPECT_EQ(base64_decode("+/+/"), (std::vector<std::uint8_t>{0xfb, 0xff, 0xbf}));
  std::vector<std::uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<std::uint8_t>(i);
  EXPECT_EQ(base64_decode(base64_encode(all)), all);
}

TEST(Base64, RoundTripsEveryLengthUpTo300) {
  std::mt19937 rng(12345);
  for (std::size_t n = 0; n <= 300; ++n) {
    std::vector<std::uint8_t> data(n);
    for (auto& b : data) b = static_cast<std::uint8_t>(rng());
    const std::string enc = base64_encode(data);
    ASSERT_EQ(enc.size(), (n + 2) / 3 * 4) << n;
    ASSERT_EQ(base64_decode(enc), data) << n;
  }
}

TEST(Base64, RefusesMalformedInput) {
  for (const char* bad : {
           "Zg=",        // length not a multiple of 4
           "Zm9vY",      // truncated group
           "Zg==Zg==",   // padding before the end
           "Z===",       // three padding characters
           "====",       // nothing but padding
           "Zm9v\n",     // whitespace is not skipped
           "Zm-v",       // URL-safe alphabet
           "Zm9v Zm9v",  // space inside
           "Zm=v",       // '=' inside a group
       }) {
    EXPECT_THROW(base64_decode(bad), std::invalid_argument) << bad;
  }
}

TEST(Endpoint, ParsesHostAndPort) {
  Endpoint ep = parse_endpoint("127.0.0.1:7878");
  EXPECT_EQ(ep.host, "127.0.0.1");
  EXPECT_EQ(ep.port, 7878);
  ep = parse_endpoint("render-box.local:1");
  EXPECT_EQ(ep.host, "render-box.local");
  EXPECT_EQ(ep.port, 1);
  ep = parse_endpoint("localhost:65535");
  EXPECT_EQ(ep.port, 65535);
  ep = parse_endpoint("[::1]:7878");
  EXPECT_EQ(ep.host, "::1");
  EXPECT_EQ(ep.port, 7878);
}

TEST(Endpoint, RefusesWithAMessageNamingTheText) {
  for (const char* bad : {
           "127.0.0.1",    // no port
           "127.0.0.1:",   // empty port
           ":7878",        // empty host
           "host:0",       // port 0 cannot be connected to
           "host:65536",   // past 16 bits
           "host:123456",  // too many digits
           "host:-1",      // sign
           "host:+80",     // sign
           "host: 80",     // space
           "host:80x",     // trailing junk
           "::1:7878",     // IPv6 without brackets
           "[::1]7878",    // no ':' after ']'
           "[::1:7878",    // unclosed bracket
           "[]:7878",      // empty bracketed host
           "",             // nothing
       }) {
    try {
      parse_endpoint(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("\"" + std::string(bad) + "\""), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace beamcast::client
