// The method list (protocol/request.hpp) is the one the server dispatches and
// announces: every listed method is answered by its handler (never
// unknown_method), hello's "methods" is the list, and the unknown-method
// error names it. PROTOCOL.md's side: tests/unit/test_protocol_methods.cpp.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "protocol/request.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

TEST(Methods, EveryListedMethodIsDispatched) {
  test::LocalServer s;
  test::Conn conn(s.port(), 60);
  int id = 0;
  for (const std::string& m : request_methods()) {
    // No params: each handler answers or rejects its params, not the method.
    const json r = conn.call({{"id", ++id}, {"method", m}}).json;
    if (r.contains("error")) {
      EXPECT_NE(r["error"]["code"], "unknown_method") << m;
    }
  }
  const json hello = conn.call({{"id", ++id}, {"method", "hello"}}).json;
  EXPECT_EQ(hello["result"]["methods"].get<std::vector<std::string>>(), request_methods());
  const json r = conn.call({{"id", ++id}, {"method", "teleport"}}).json;
  EXPECT_EQ(r["error"]["code"], "unknown_method");
  EXPECT_NE(r["error"]["message"].get<std::string>().find(request_methods_text()),
            std::string::npos);
}

}  // namespace
}  // namespace beamcast
