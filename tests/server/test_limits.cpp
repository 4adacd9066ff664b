// The settings table (server/settings.hpp) against the documents: its limit
// rows against PROTOCOL.md's "Limits" table (the same names, the same
// defaults), every row against the guide's table, which is its output; hello
// and stats report exactly the table; the command line is made from it.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "protocol/scene_json.hpp"
#include "protocol/volume.hpp"
#include "server/settings.hpp"

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

std::vector<const Setting*> rows_of(SettingKind kind) {
  std::vector<const Setting*> out;
  for (const Setting& s : settings_table()) {
    if (s.kind == kind) out.push_back(&s);
  }
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/" + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Limits, TableMatchesProtocolMd) {
  const auto documented = protocol_md_limits();
  const ServerConfig defaults;
  ASSERT_FALSE(documented.empty());
  for (const Setting* e : rows_of(SettingKind::kLimit)) {
    const auto it = documented.find(std::string(e->name));
    ASSERT_NE(it, documented.end()) << e->name << " is a limit but not in PROTOCOL.md's table";
    EXPECT_EQ(it->second, e->get(defaults).get<std::int64_t>())
        << e->name << ": PROTOCOL.md and ServerConfig disagree";
  }
  for (const auto& [name, value] : documented) {
    const Setting* s = find_setting(name);
    EXPECT_TRUE(s && s->kind == SettingKind::kLimit)
        << name << " is in PROTOCOL.md's table but not a limit row of server/settings.cpp";
  }
}

// docs/guide/server-settings.md holds settings_markdown()'s table between its
// markers (regenerate: build/bin/beamcast-server --settings-markdown).
TEST(Limits, TheGuidesTableIsTheSettingsTable) {
  const std::string doc = read_file("docs/guide/server-settings.md");
  const std::string begin = "<!-- settings table: begin -->\n", end = "<!-- settings table: end -->";
  const std::size_t a = doc.find(begin), b = doc.find(end);
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  EXPECT_EQ(doc.substr(a + begin.size(), b - a - begin.size()), settings_markdown(server_defaults()))
      << "regenerate the table with build/bin/beamcast-server --settings-markdown";
}

TEST(Limits, HelloReportsEveryLimitAndSetWritesTheConfig) {
  ServerConfig c;
  for (const Setting* e : rows_of(SettingKind::kLimit)) {
    const std::int64_t v = e->get(c).get<std::int64_t>();
    e->set(c, v == 1 ? 2 : v - 1);
  }
  const nlohmann::json j = limits_json(c);
  EXPECT_EQ(j.size(), rows_of(SettingKind::kLimit).size() + rows_of(SettingKind::kFixed).size());
  for (const Setting* e : rows_of(SettingKind::kLimit)) {
    EXPECT_EQ(j.at(std::string(e->name)), e->get(c)) << e->name;
    EXPECT_NE(e->get(c), e->get(ServerConfig{})) << e->name << ": set did not reach the config";
    EXPECT_TRUE(e->option().starts_with("--max-") || e->option().ends_with("-timeout-ms"))
        << e->option();
  }
  // Fixed rows: reported, never options; the scene format's bounds among them.
  for (const Setting* e : rows_of(SettingKind::kFixed)) {
    EXPECT_EQ(j.at(std::string(e->name)), e->get(c)) << e->name;
    EXPECT_FALSE(e->set) << e->name;
  }
  EXPECT_EQ(j.at("max_supersample"), kMaxSupersample);
  EXPECT_EQ(j.at("max_volume_dimension"), kMaxVolumeDimension);
  // Options are not limits.
  EXPECT_FALSE(j.contains("render_workers"));
}

// stats' settings: every row but the token, whose value never leaves the server.
TEST(Limits, StatsReportEverySettingButTheToken) {
  ServerConfig c = server_defaults();
  c.token = "s3cret";
  const nlohmann::json j = settings_json(c);
  EXPECT_EQ(j.size(), settings_table().size() - 1);
  EXPECT_FALSE(j.contains("token"));
  EXPECT_EQ(j.dump().find("s3cret"), std::string::npos);
  EXPECT_EQ(j.at("http_port"), 7879);
  EXPECT_EQ(j.at("render_workers"), 1);
  EXPECT_EQ(j.at("png_encoder"), "libdeflate");
  EXPECT_EQ(j.at("max_width"), 4096);
}

// What is checked across rows after the command line: the PNG level's
// default per encoder, libpng-only filters, TLS files in pairs.
TEST(Limits, CrossChecksAfterTheCommandLine) {
  ServerConfig c = server_defaults();
  find_setting("png_encoder")->set(c, "libpng");
  EXPECT_EQ(finish_settings(c, {}), "");
  EXPECT_EQ(c.png.level, 2);  // libpng's default level
  find_setting("png_level")->set(c, 12);
  EXPECT_NE(finish_settings(c, {"png_level"}).find("0..9"), std::string::npos);
  ServerConfig d = server_defaults();
  EXPECT_EQ(finish_settings(d, {}), "");
  EXPECT_EQ(d.png.level, 1);
  find_setting("png_filter")->set(d, "paeth");
  EXPECT_NE(finish_settings(d, {}).find("needs --png-encoder libpng"), std::string::npos);
  ServerConfig t = server_defaults();
  find_setting("tls_cert")->set(t, "cert.pem");
  EXPECT_NE(finish_settings(t, {}).find("--tls-key"), std::string::npos);
  find_setting("tls_key")->set(t, "key.pem");
  EXPECT_EQ(finish_settings(t, {}), "");
  // Flags: given means set.
  ServerConfig f = server_defaults();
  find_setting("quiet_requests")->set(f, true);
  find_setting("no_demo")->set(f, true);
  EXPECT_FALSE(f.request_log);
  EXPECT_FALSE(f.preload_demo);
}

}  // namespace
}  // namespace beamcast
