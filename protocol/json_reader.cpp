#include "protocol/json_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

namespace beamcast::json_read {

using nlohmann::json;

void fail(std::string code, std::string path, std::string message) {
  throw ProtocolError(ErrorInfo{std::move(code), std::move(message), std::move(path)});
}

std::string child_path(const std::string& path, std::string_view key) {
  std::string out = path;
  out += '/';
  for (char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string child_path(const std::string& path, std::size_t index) {
  return path + "/" + std::to_string(index);
}

std::string format_number(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

namespace {

// Clips long strings so a hostile 1 MB value does not end up in a log line.
std::string clip(std::string s) {
  constexpr std::size_t kMax = 64;
  if (s.size() > kMax) s = s.substr(0, kMax) + "...";
  return s;
}

}  // namespace

std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case json::value_t::string:
      return "string " + clip(v.dump(-1, ' ', true, json::error_handler_t::replace));
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return v.dump();
    case json::value_t::number_float:
      return format_number(v.get<double>());
    case json::value_t::array:
      return "array of " + std::to_string(v.size()) + (v.size() == 1 ? " value" : " values");
    case json::value_t::object:
      return "object";
    default:
      return v.type_name();
  }
}

std::string Node::name() const {
  // Last pointer token, or "parent[index]" when the last token is an array index.
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return "scene";
  std::string last = path.substr(slash + 1);
  const bool is_index = !last.empty() && std::all_of(last.begin(), last.end(),
                                                     [](char c) { return c >= '0' && c <= '9'; });
  if (!is_index || slash == 0) return last;
  const auto prev = path.rfind('/', slash - 1);
  const std::string parent = path.substr(prev + 1, slash - prev - 1);
  return parent + "[" + last + "]";
}

ObjectReader::ObjectReader(const Node& node, std::string_view what)
    : obj_(node.value), path_(node.path), what_(what) {
  if (!obj_->is_object()) {
    fail("wrong_type", path_,
         node.name() + " must be " + what_ + " (a JSON object), got " + describe(*obj_));
  }
}

void ObjectReader::allow_only(std::initializer_list<std::string_view> allowed) const {
  allow_only(std::span<const std::string_view>(allowed.begin(), allowed.size()));
}

void ObjectReader::allow_only(std::span<const std::string_view> allowed) const {
  for (const auto& item : obj_->items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string list;
    for (std::string_view a : allowed) {
      if (!list.empty()) list += ", ";
      list += a;
    }
    fail("unknown_field", child_path(path_, key),
         "unknown field \"" + clip(key) + "\" in " + what_ + "; allowed fields: " + list);
  }
}

std::optional<Node> ObjectReader::optional(std::string_view key) const {
  const auto it = obj_->find(key);
  if (it == obj_->end()) return std::nullopt;
  return Node{&*it, child_path(path_, key)};
}

Node ObjectReader::required(std::string_view key) const {
  auto n = optional(key);
  if (!n) {
    fail("missing_field", child_path(path_, key),
         "required field \"" + std::string(key) + "\" is missing from " + what_);
  }
  return *n;
}

double read_number(const Node& n) {
  if (!n.json().is_number()) {
    fail("wrong_type", n.path, n.name() + " must be a number, got " + describe(n.json()));
  }
  const double v = n.json().get<double>();
  if (!std::isfinite(v)) {
    fail("not_finite", n.path, n.name() + " must be a finite number, got " + format_number(v));
  }
  // Subnormal numbers (0 < |v| < 2.2e-308) overflow when inverted and lose
  // their digits in any product: no scene quantity needs one (issue 43).
  if (v != 0.0 && std::fpclassify(v) == FP_SUBNORMAL) {
    fail("out_of_range", n.path,
         n.name() + " must be 0 or of magnitude >= " +
             format_number(std::numeric_limits<double>::min()) +
             " (subnormal numbers are refused), got " + format_number(v));
  }
  return v;
}

std::int64_t read_integer(const Node& n) {
  const json& j = n.json();
  constexpr std::uint64_t kMaxMagnitude = 1ULL << 53;  // beyond this nothing is in range anyway
  if (j.is_number_unsigned()) {
    if (j.get<std::uint64_t>() > kMaxMagnitude) {
      fail("out_of_range", n.path, n.name() + " is far too large, got " + j.dump());
    }
    return static_cast<std::int64_t>(j.get<std::uint64_t>());
  }
  if (j.is_number_integer()) return j.get<std::int64_t>();
  const double v = read_number(n);
  if (v != std::floor(v)) {
    fail("wrong_type", n.path, n.name() + " must be an integer, got " + format_number(v));
  }
  if (std::abs(v) > 9.0e15) {
    fail("out_of_range", n.path, n.name() + " is far too large, got " + format_number(v));
  }
  return static_cast<std::int64_t>(v);
}

bool read_bool(const Node& n) {
  if (!n.json().is_boolean()) {
    fail("wrong_type", n.path, n.name() + " must be true or false, got " + describe(n.json()));
  }
  return n.json().get<bool>();
}

std::string read_string(const Node& n) {
  if (!n.json().is_string()) {
    fail("wrong_type", n.path, n.name() + " must be a string, got " + describe(n.json()));
  }
  return n.json().get<std::string>();
}

std::vector<Node> read_array(const Node& n, std::int64_t max_size, std::string_view limit_name) {
  if (!n.json().is_array()) {
    fail("wrong_type", n.path, n.name() + " must be an array, got " + describe(n.json()));
  }
  const auto size = static_cast<std::int64_t>(n.json().size());
  if (max_size >= 0 && size > max_size) {
    fail("limit_exceeded", n.path,
         n.name() + " has " + std::to_string(size) + " entries, over the limit " +
             std::string(limit_name) + " = " + std::to_string(max_size));
  }
  std::vector<Node> out;
  out.reserve(n.json().size());
  for (std::size_t i = 0; i < n.json().size(); ++i) {
    out.push_back(Node{&n.json()[i], child_path(n.path, i)});
  }
  return out;
}

template <std::size_t N>
std::array<double, N> read_numbers(const Node& n) {
  if (!n.json().is_array() || n.json().size() != N) {
    fail("wrong_type", n.path,
         n.name() + " must be an array of " + std::to_string(N) + " numbers, got " +
             describe(n.json()));
  }
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) {
    out[i] = read_number(Node{&n.json()[i], child_path(n.path, i)});
  }
  return out;
}
template std::array<double, 2> read_numbers<2>(const Node&);
template std::array<double, 3> read_numbers<3>(const Node&);
template std::array<double, 4> read_numbers<4>(const Node&);
template std::array<double, 6> read_numbers<6>(const Node&);

Vec3 read_vec3(const Node& n) { return read_numbers<3>(n); }

double check_positive(const Node& n, double v) {
  if (!(v > 0.0)) {
    fail("out_of_range", n.path, n.name() + " must be > 0 and finite, got " + format_number(v));
  }
  return v;
}

double check_non_negative(const Node& n, double v) {
  if (!(v >= 0.0)) {
    fail("out_of_range", n.path, n.name() + " must be >= 0 and finite, got " + format_number(v));
  }
  return v;
}

double check_closed(const Node& n, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi)) {
    fail("out_of_range", n.path,
         n.name() + " must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " +
             format_number(v));
  }
  return v;
}

double check_open(const Node& n, double v, double lo, double hi) {
  if (!(v > lo && v < hi)) {
    fail("out_of_range", n.path,
         n.name() + " must be in (" + format_number(lo) + ", " + format_number(hi) +
             ") exclusive, got " + format_number(v));
  }
  return v;
}

Vec3 check_coordinates(const Node& n, const Vec3& v, double max_abs) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::abs(v[i]) > max_abs) {
      const Node c{&n.json()[i], child_path(n.path, i)};
      fail("out_of_range", c.path,
           c.name() + " must have magnitude <= " + format_number(max_abs) +
               " (limit max_abs_coordinate), got " + format_number(v[i]));
    }
  }
  return v;
}

}  // namespace beamcast::json_read
