// The one table of beamcast-server's settings (issue 41, item 4): every
// command-line option, every limit a client can run into and every fixed
// bound of the scene format the server enforces, one row each with its name,
// kind, range or choices, help line and where it lives in ServerConfig.
// From it come beamcast-server's options (server/main.cpp adds one per row
// that is not fixed), hello's `limits` (the limit and fixed rows), stats'
// `settings` (every row but the token) and the checks against
// PROTOCOL.md's "Limits" table and the guide's option table
// (tests/server/test_limits.cpp). A new setting is one row here, its field
// in server/config.hpp and its line in the documents the test reads.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/config.hpp"

namespace beamcast {

enum class SettingKind {
  kOption,  // how the server runs (ports, threads, encoders): an option, in stats
  kLimit,   // what a request may ask for: an option, in hello's limits and stats
  kFixed,   // a bound compiled in (the scene format's, the renderer's): in hello's limits and stats
};

enum class SettingType {
  kInteger,  // an integer in [min, max]
  kNumber,   // a floating-point number (fixed rows only)
  kText,     // a string; one of `choices` if any
  kFlag,     // present or not (a command-line flag)
};

struct Setting {
  std::string_view name;  // as in hello, stats and the documents: "max_width"
  SettingKind kind = SettingKind::kOption;
  SettingType type = SettingType::kInteger;
  std::int64_t min = 0, max = 0;           // kInteger: the values accepted
  std::vector<std::string_view> choices;   // kText: the values accepted (empty: any)
  std::string_view help;
  std::string_view env;  // environment variable read when the option is absent, or empty
  bool secret = false;   // never reported (the token)
  std::function<nlohmann::json(const ServerConfig&)> get;
  // Writes a value of the row's type into the config; null for fixed rows.
  std::function<void(ServerConfig&, const nlohmann::json&)> set;

  // "--max-width": the name with dashes.
  std::string option() const;
};

const std::vector<Setting>& settings_table();

// beamcast-server's defaults: ServerConfig's, with the HTTP listener on
// (7879) and the request log on. (The assets directory, found at start-up
// beside the binary, is set by main.)
ServerConfig server_defaults();

// The guide's table of every setting (docs/guide/server-settings.md, between
// its markers), from the table and `defaults`: `beamcast-server
// --settings-markdown` prints it, and a test checks the guide against it.
std::string settings_markdown(const ServerConfig& defaults);
// The row named `name`, or null.
const Setting* find_setting(std::string_view name);

// hello's "limits": every limit and fixed row with its value in `c`.
nlohmann::json limits_json(const ServerConfig& c);
// stats' "settings": every row but the secret ones, with its value in `c`.
nlohmann::json settings_json(const ServerConfig& c);

// What is checked across rows once the command line is read: the PNG
// level's default per encoder (when `given` lacks "png_level") and its
// range, a filter only libpng has, a TLS certificate without its key.
// Returns the first problem as a message for the command line, or "".
std::string finish_settings(ServerConfig& c, const std::set<std::string>& given);

}  // namespace beamcast
