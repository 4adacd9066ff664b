#include "protocol/bounded_json.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "protocol/json_reader.hpp"

namespace beamcast {
namespace {

using json = nlohmann::json;

// nlohmann's exception ids (json.exception.<kind>.<id>) this parser tells apart.
constexpr int kSyntaxError = 101;
constexpr int kNumberOverflow = 406;

// Retries of the top-level-scalar recovery after a number overflow: each one
// rescans the text with the overflowing token blanked out.
constexpr int kMaxOverflowRescans = 8;

std::string clip(std::string_view s, std::size_t n = 40) {
  return s.size() <= n ? std::string(s) : std::string(s.substr(0, n)) + "...";
}

// An open container while parsing: where its children go and which child is
// current, for error paths.
struct Level {
  json* container = nullptr;  // null while skipping (past a limit)
  bool is_array = false;
  std::string key;            // objects: the key of the current member
  std::size_t count = 0;      // arrays: elements placed so far
};

// nlohmann's SAX interface (json::sax_parse): builds the document like its own
// DOM parser, but with limits and JSON-pointer bookkeeping.
class BoundedBuilder {
 public:
  BoundedBuilder(std::string_view text, const JsonLimits& limits, bool recover, bool skip_all)
      : text_(text), limits_(limits), recover_(recover), skipping_(skip_all) {}

  bool null() { return scalar(json(nullptr)); }
  bool boolean(bool v) { return scalar(json(v)); }
  bool number_integer(json::number_integer_t v) { return scalar(json(v)); }
  bool number_unsigned(json::number_unsigned_t v) { return scalar(json(v)); }
  bool number_float(json::number_float_t v, const json::string_t&) { return scalar(json(v)); }
  bool string(json::string_t& v) { return scalar(json(std::move(v))); }
  bool binary(json::binary_t&) { return scalar(json(nullptr)); }  // not produced from JSON text

  bool start_object(std::size_t) { return open(false); }
  bool start_array(std::size_t) { return open(true); }
  bool key(json::string_t& k) {
    levels_.back().key = std::move(k);
    return true;
  }
  bool end_object() { return close(); }
  bool end_array() { return close(); }

  bool parse_error(std::size_t position, const std::string& last_token, const json::exception& ex) {
    overflow_ = ex.id == kNumberOverflow;
    overflow_end_ = position;
    overflow_token_ = last_token;
    if (error_) return false;  // a limit error came first (recovery mode)
    // nlohmann reports the position after the last character it read: for a
    // number overflow that is the end of the number (point at its start); for
    // a syntax error, the offending character is the last one read.
    const std::size_t offset =
        ex.id == kNumberOverflow
            ? (position >= last_token.size() ? position - last_token.size() : 0)
            : (position > 0 ? position - 1 : 0);
    const std::string where = location(offset);
    if (ex.id == kNumberOverflow) {
      set_error("not_finite", "the number " + clip(last_token) + " " + where +
                                  " is too large for a double");
    } else if (ex.id == kSyntaxError) {
      set_error("bad_json", "the message is not valid JSON: " + syntax_reason(ex, last_token) +
                                " " + where);
    } else {
      set_error("bad_json", "the message is not valid JSON " + where);
    }
    return false;
  }

  json& root() { return root_; }
  std::optional<ErrorInfo>& error() { return error_; }
  bool overflow() const { return overflow_; }
  std::size_t overflow_end() const { return overflow_end_; }
  const std::string& overflow_token() const { return overflow_token_; }

 private:
  // The pointer of the value about to be placed (or of the current position).
  std::string current_path() const {
    std::string path;
    for (std::size_t i = 0; i < levels_.size(); ++i) {
      const Level& l = levels_[i];
      const bool innermost = i + 1 == levels_.size();
      std::string seg;
      if (l.is_array) {
        seg = json_read::child_path("", innermost ? l.count : (l.count == 0 ? 0 : l.count - 1));
      } else {
        seg = json_read::child_path("", l.key);
      }
      if (path.size() + seg.size() > kMaxErrorPathBytes) break;
      path += seg;
    }
    return path;
  }

  // "at byte 12 (line 1, column 13)": byte offsets from 0, lines and columns
  // (in bytes) from 1.
  std::string location(std::size_t offset) const {
    offset = std::min(offset, text_.size());
    const std::string_view before = text_.substr(0, offset);
    const std::size_t line = 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t nl = before.rfind('\n');
    const std::size_t column = nl == std::string_view::npos ? offset + 1 : offset - nl;
    return "at byte " + std::to_string(offset) + " (line " + std::to_string(line) + ", column " +
           std::to_string(column) + ")";
  }

  static std::string syntax_reason(const json::exception& ex, const std::string& token) {
    const std::string_view what = ex.what();
    if (what.find("ill-formed UTF-8") != std::string_view::npos) {
      return "a string holds bytes that are not UTF-8";
    }
    if (what.find("control character") != std::string_view::npos) {
      return "a string holds an unescaped control character";
    }
    if (what.find("unexpected end of input") != std::string_view::npos || token.empty()) {
      return "the text ends before the JSON value does";
    }
    if (what.find("\\u") != std::string_view::npos || what.find("surrogate") != std::string_view::npos) {
      return "a string holds an invalid \\u escape";
    }
    if (what.find("invalid number") != std::string_view::npos) return "a malformed number";
    if (what.find("invalid literal") != std::string_view::npos) {
      return "an unknown word (only true, false and null are allowed)";
    }
    return "unexpected text";
  }

  void set_error(std::string code, std::string message) {
    error_ = ErrorInfo{std::move(code), std::move(message), current_path()};
  }

  // A limit was hit: record it; with recovery, go on lexing without building.
  bool limit(std::string message) {
    set_error("limit_exceeded", std::move(message));
    skipping_ = true;
    return recover_;
  }

  json* place(json&& v) {
    if (levels_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Level& top = levels_.back();
    if (top.is_array) {
      auto& a = *top.container->get_ptr<json::array_t*>();
      a.push_back(std::move(v));
      ++top.count;
      return &a.back();
    }
    auto& o = *top.container->get_ptr<json::object_t*>();
    json& slot = o[top.key];  // a repeated key: the last one wins, as in nlohmann's parser
    slot = std::move(v);
    return &slot;
  }

  bool count_value() {
    if (++values_ <= limits_.max_values) return true;
    return limit("the document holds more than max_json_values (" +
                 std::to_string(limits_.max_values) + ") values");
  }

  bool scalar(json&& v) {
    if (skipping_) {
      // Recovery keeps the root object's own scalars (a request's id).
      if (recover_ && levels_.size() == 1 && !levels_[0].is_array) place(std::move(v));
      return true;
    }
    if (!count_value()) return false;
    if (skipping_) return true;  // this value was one too many
    place(std::move(v));
    return true;
  }

  bool open(bool is_array) {
    Level l;
    l.is_array = is_array;
    if (levels_.empty()) {
      // The root is always built (recovery fills its scalars).
      root_ = is_array ? json::array() : json::object();
      l.container = &root_;
      if (!skipping_) ++values_;
      levels_.push_back(std::move(l));
      if (!skipping_ && limits_.max_depth < 1) {
        return limit("the document nests deeper than max_json_depth (" +
                     std::to_string(limits_.max_depth) + ")");
      }
      return true;
    }
    if (!skipping_) {
      if (static_cast<int>(levels_.size()) + 1 > limits_.max_depth) {
        if (!limit("the document nests deeper than max_json_depth (" +
                   std::to_string(limits_.max_depth) + ")")) {
          return false;
        }
      } else if (!count_value()) {
        return false;
      }
    }
    if (!skipping_) l.container = place(is_array ? json::array() : json::object());
    levels_.push_back(std::move(l));
    return true;
  }

  bool close() {
    levels_.pop_back();
    return true;
  }

  std::string_view text_;
  JsonLimits limits_;
  bool recover_;
  bool skipping_;
  json root_;
  std::vector<Level> levels_;
  std::int64_t values_ = 0;
  std::optional<ErrorInfo> error_;
  bool overflow_ = false;
  std::size_t overflow_end_ = 0;
  std::string overflow_token_;
};

bool run(std::string_view text, BoundedBuilder* b) {
  return json::sax_parse(text.begin(), text.end(), b, json::input_format_t::json, /*strict=*/true);
}

// Blanks the overflowing number token ending at `end` ("1e999" -> "0    ");
// false if the token cannot be found there.
bool blank_token(std::string* text, std::size_t end, const std::string& token) {
  for (std::size_t back : {std::size_t{0}, std::size_t{1}}) {
    if (end < token.size() + back || end - back > text->size()) continue;
    const std::size_t start = end - back - token.size();
    if (text->compare(start, token.size(), token) == 0) {
      (*text)[start] = '0';
      std::fill(text->begin() + static_cast<std::ptrdiff_t>(start) + 1,
                text->begin() + static_cast<std::ptrdiff_t>(start + token.size()), ' ');
      return true;
    }
  }
  return false;
}

}  // namespace

BoundedParse parse_json_bounded(std::string_view text, const JsonLimits& limits,
                                bool recover_top_level_scalars) {
  BoundedBuilder b(text, limits, recover_top_level_scalars, /*skip_all=*/false);
  const bool ok = run(text, &b);
  BoundedParse out;
  if (ok && !b.error()) {
    out.value = std::move(b.root());
    return out;
  }
  out.error = b.error();
  if (!out.error) out.error = ErrorInfo{"bad_json", "the message is not valid JSON", ""};
  if (!recover_top_level_scalars) return out;
  out.value = b.root().is_object() ? std::move(b.root()) : json::object();
  if (!b.overflow()) return out;
  // A number overflow stops nlohmann's lexer, so members after it (an id
  // written last) are not read yet: rescan with the token blanked out,
  // building nothing but the root's scalars.
  std::string patched(text);
  bool overflow = true;
  std::size_t end = b.overflow_end();
  std::string token = b.overflow_token();
  for (int i = 0; overflow && i < kMaxOverflowRescans; ++i) {
    if (!blank_token(&patched, end, token)) break;
    BoundedBuilder again(patched, limits, /*recover=*/true, /*skip_all=*/true);
    run(patched, &again);
    if (again.root().is_object()) {
      for (auto& [k, v] : again.root().items()) out.value[k] = v;
    }
    overflow = again.overflow();
    end = again.overflow_end();
    token = again.overflow_token();
  }
  return out;
}

json parse_json_or_throw(std::string_view text, const JsonLimits& limits) {
  BoundedParse p = parse_json_bounded(text, limits);
  if (p.error) throw ProtocolError(std::move(*p.error));
  return std::move(p.value);
}

int json_depth(const json& j) {
  int deepest = 0;
  std::vector<std::pair<const json*, int>> stack{{&j, 0}};
  while (!stack.empty()) {
    auto [v, d] = stack.back();
    stack.pop_back();
    if (!v->is_structured()) continue;
    deepest = std::max(deepest, d + 1);
    for (const json& child : *v) stack.push_back({&child, d + 1});
  }
  return deepest;
}

}  // namespace beamcast
