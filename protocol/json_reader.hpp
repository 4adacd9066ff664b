// Typed, path-tracking reads from nlohmann::json for scene validation.
// Internal to protocol/: every failure throws ProtocolError carrying the RFC 6901
// pointer of the offending value and a one-sentence message naming the value
// and the rule it broke.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "protocol/errors.hpp"
#include "protocol/scene.hpp"

namespace beamcast::json_read {

[[noreturn]] void fail(std::string code, std::string path, std::string message);

// RFC 6901: "~" -> "~0", "/" -> "~1".
std::string child_path(const std::string& path, std::string_view key);
std::string child_path(const std::string& path, std::size_t index);

// Shortest text that round-trips (e.g. "-1", "0.1", "1e+300").
std::string format_number(double v);
// A short description of a JSON value for messages: `string "abc"`, `array of 2 values`.
std::string describe(const nlohmann::json& v);

// A JSON value and its pointer. The value is borrowed from the document.
struct Node {
  const nlohmann::json* value;
  std::string path;

  const nlohmann::json& json() const { return *value; }
  // Human name of the field for messages: "radius", "center[1]", "beams[3]".
  std::string name() const;
};

// A JSON object being read. Unknown keys are rejected up front (so a typo is
// reported as the typo, not as the missing field it was meant to be).
class ObjectReader {
 public:
  // Throws wrong_type if `node` is not an object; `what` names it ("a beam").
  ObjectReader(const Node& node, std::string_view what);

  // Throws unknown_field for the first key not in `allowed`, listing the allowed keys.
  void allow_only(std::initializer_list<std::string_view> allowed) const;
  void allow_only(std::span<const std::string_view> allowed) const;

  std::optional<Node> optional(std::string_view key) const;
  Node required(std::string_view key) const;  // throws missing_field
  std::string path_of(std::string_view key) const { return child_path(path_, key); }
  const std::string& path() const { return path_; }

 private:
  const nlohmann::json* obj_;
  std::string path_;
  std::string what_;
};

// Scalars. Numbers must be finite ("not_finite"), of the right JSON type ("wrong_type").
double read_number(const Node& n);
// An integer; integral floats such as 512.0 are accepted.
std::int64_t read_integer(const Node& n);
bool read_bool(const Node& n);
std::string read_string(const Node& n);

// Arrays. `read_array` also enforces a maximum length (code "limit_exceeded",
// naming `limit_name`); pass -1 for no maximum.
std::vector<Node> read_array(const Node& n, std::int64_t max_size = -1,
                             std::string_view limit_name = {});
// Exactly N finite numbers.
template <std::size_t N>
std::array<double, N> read_numbers(const Node& n);
Vec3 read_vec3(const Node& n);

// Range checks on already-read values; they throw "out_of_range" naming the
// rule ("radius must be > 0 and finite, got -1").
double check_positive(const Node& n, double v);
double check_non_negative(const Node& n, double v);
double check_closed(const Node& n, double v, double lo, double hi);
double check_open(const Node& n, double v, double lo, double hi);
// |v| <= max_abs for every component; `n` is the vector's node.
Vec3 check_coordinates(const Node& n, const Vec3& v, double max_abs);

// String enumerations: "invalid_value" listing the allowed strings.
template <class E>
E read_enum(const Node& n, std::span<const std::pair<std::string_view, E>> options) {
  const std::string s = read_string(n);
  std::string allowed;
  for (const auto& [name, value] : options) {
    if (s == name) return value;
    if (!allowed.empty()) allowed += ", ";
    allowed += '"';
    allowed += name;
    allowed += '"';
  }
  fail("invalid_value", n.path,
       n.name() + " must be one of " + allowed + ", got " + describe(n.json()));
}
template <class E>
E read_enum(const Node& n, std::initializer_list<std::pair<std::string_view, E>> options) {
  return read_enum<E>(n, std::span<const std::pair<std::string_view, E>>(options.begin(),
                                                                         options.size()));
}
// The names of a table of options, for capability lists.
template <class E, std::size_t N>
std::vector<std::string_view> enum_names(const std::array<std::pair<std::string_view, E>, N>& t) {
  std::vector<std::string_view> names;
  for (const auto& [name, value] : t) names.push_back(name);
  return names;
}

}  // namespace beamcast::json_read
