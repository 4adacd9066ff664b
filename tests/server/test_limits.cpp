// The limits table (server/limits.hpp) against PROTOCOL.md's: the same names,
// the same defaults, and hello reports exactly the table.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "server/limits.hpp"

namespace beamcast {
namespace {

// "16 MiB" -> 16777216, "16 777 216" -> 16777216, "300 000" -> 300000.
std::int64_t parse_default(std::string text) {
  std::int64_t scale = 1;
  for (const auto& [suffix, factor] : {std::pair<std::string, std::int64_t>{" MiB", 1 << 20},
                                       {" KiB", 1 << 10}}) {
    if (text.size() > suffix.size() && text.ends_with(suffix)) {
      text.resize(text.size() - suffix.size());
      scale = factor;
    }
  }
  std::string digits;
  for (char ch : text) {
    if (ch != ' ') digits += ch;
  }
  return std::stoll(digits) * scale;
}

// name -> default, from the rows of the "## Limits" table of PROTOCOL.md.
std::map<std::string, std::int64_t> protocol_md_limits() {
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/protocol/PROTOCOL.md");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::size_t start = doc.find("\n## Limits");
  EXPECT_NE(start, std::string::npos);
  std::map<std::string, std::int64_t> out;
  std::istringstream lines(doc.substr(start));
  std::string line;
  bool in_table = false;
  while (std::getline(lines, line)) {
    if (line.starts_with("| limit ")) {
      in_table = true;
      continue;
    }
    if (!in_table) continue;
    if (!line.starts_with("|")) break;
    if (line.starts_with("|---")) continue;
    // | `max_scenes`, `max_scene_store_bytes` | 256, 64 MiB | effect |
    const std::size_t c1 = line.find('|', 1), c2 = line.find('|', c1 + 1);
    const std::string names_cell = line.substr(1, c1 - 1);
    std::string defaults_cell = line.substr(c1 + 1, c2 - c1 - 1);
    std::vector<std::string> names, defaults;
    const std::regex name_re("`([a-z_]+)`");
    for (auto it = std::sregex_iterator(names_cell.begin(), names_cell.end(), name_re);
         it != std::sregex_iterator(); ++it) {
      names.push_back((*it)[1]);
    }
    std::istringstream ds(defaults_cell);
    std::string d;
    while (std::getline(ds, d, ',')) {
      d.erase(0, d.find_first_not_of(' '));
      d.erase(d.find_last_not_of(' ') + 1);
      defaults.push_back(d);
    }
    for (std::size_t i = 0; i < names.size(); ++i) {
      out[names[i]] = parse_default(defaults.size() == names.size() ? defaults[i] : defaults[0]);
    }
  }
  return out;
}

TEST(Limits, TableMatchesProtocolMd) {
  const auto documented = protocol_md_limits();
  const ServerConfig defaults;
  ASSERT_FALSE(documented.empty());
  for (const LimitEntry& e : limit_table()) {
    const auto it = documented.find(std::string(e.name));
    ASSERT_NE(it, documented.end()) << e.name << " is a limit but not in PROTOCOL.md's table";
    EXPECT_EQ(it->second, e.get(defaults)) << e.name << ": PROTOCOL.md and ServerConfig disagree";
  }
  for (const auto& [name, value] : documented) {
    bool found = false;
    for (const LimitEntry& e : limit_table()) found |= e.name == name;
    EXPECT_TRUE(found) << name << " is in PROTOCOL.md's table but not in server/limits.cpp";
  }
}

TEST(Limits, HelloReportsEveryLimitAndSetWritesTheConfig) {
  ServerConfig c;
  for (const LimitEntry& e : limit_table()) e.set(c, e.get(c) == 1 ? 2 : e.get(c) - 1);
  const nlohmann::json j = limits_json(c);
  EXPECT_EQ(j.size(), limit_table().size());
  for (const LimitEntry& e : limit_table()) {
    EXPECT_EQ(j.at(std::string(e.name)).get<std::int64_t>(), e.get(c)) << e.name;
    EXPECT_NE(e.get(c), e.get(ServerConfig{})) << e.name << ": set did not reach the config";
    EXPECT_TRUE(e.option().starts_with("--max-") || e.option().ends_with("-timeout-ms"))
        << e.option();
  }
}

}  // namespace
}  // namespace beamcast
