// The one table of the server's limits (PROTOCOL.md, "Limits"), Redis-style:
// each limit's name, where it lives in ServerConfig, the range its option
// accepts and a line of help. beamcast-server's options (--max-width ...),
// hello's "limits" object and the test that compares with PROTOCOL.md's table
// (tests/unit/test_limits.cpp) are all generated from it, so a new limit is
// one line here plus its row in PROTOCOL.md.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/config.hpp"

namespace beamcast {

struct LimitEntry {
  std::string_view name;  // as in PROTOCOL.md and hello: "max_width"
  std::int64_t min, max;  // accepted option values
  std::string_view help;
  std::function<std::int64_t(const ServerConfig&)> get;
  std::function<void(ServerConfig&, std::int64_t)> set;

  // "--max-width": the name with dashes.
  std::string option() const;
};

const std::vector<LimitEntry>& limit_table();

// hello's "limits": every entry of the table with its value in `c`.
nlohmann::json limits_json(const ServerConfig& c);

}  // namespace beamcast
