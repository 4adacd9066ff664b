// PROTOCOL.md's "## Methods" section documents exactly the methods of
// request_methods() (protocol/request.hpp), in the same order: one "### `name`"
// heading each. The server's side: tests/server/test_methods.cpp.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "protocol/request.hpp"

namespace beamcast {
namespace {

TEST(ProtocolMethods, DocumentedMethodsAreTheList) {
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/protocol/PROTOCOL.md");
  ASSERT_TRUE(in) << "cannot read PROTOCOL.md";
  std::vector<std::string> documented;
  bool in_methods = false;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("## ")) in_methods = line == "## Methods";
    // "### `scene.put`"; other ### headings in the section (e.g. "### Interactive
    // quality") are not methods.
    if (in_methods && line.starts_with("### `") && line.ends_with("`")) {
      documented.push_back(line.substr(5, line.size() - 6));
    }
  }
  EXPECT_EQ(documented, request_methods());
}

}  // namespace
}  // namespace beamcast
