// JSON parsing with limits enforced while parsing (PROTOCOL.md, "Limits":
// max_json_depth, max_json_values). Every byte a client sends goes through
// here, so no later recursive walk over a client's document (copy, merge
// patch, validation, echo, serialization) can be deeper than max_json_depth,
// and no document holds more than max_json_values values.
//
// nlohmann's parser itself is iterative; the document it builds is not safe to
// walk recursively (copying, dump, operator==, merge_patch all recurse), which
// is how one 360 KB request of 60 000 nested objects overflowed the server's
// stack. This parser drives nlohmann's SAX interface and refuses the first
// container past the depth limit, before building it.
//
// Errors carry the JSON pointer of the offending value and messages in this
// project's words (never the library's exception text).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"

namespace beamcast {

struct JsonLimits {
  // Containers nested deeper than this are refused: the root object or array
  // is depth 1. 64 is 8x the deepest document the protocol defines (a table
  // density inside a scene inside a request is depth 7).
  int max_depth = 64;
  // Values (objects, arrays and scalars, keys not counted) in one document.
  std::int64_t max_values = 1'000'000;
};

// Longest error path reported; a deeper pointer is cut back to its longest
// prefix of whole segments within this many bytes (it then names an ancestor
// of the bad value). Keys are client-chosen and unbounded in length.
inline constexpr std::size_t kMaxErrorPathBytes = 1024;

struct BoundedParse {
  nlohmann::json value;
  // The first error: bad_json (syntax), not_finite (a number beyond double),
  // limit_exceeded (depth or value count). When set, `value` is not the
  // document: it holds only what `top_level_scalars` recovered.
  std::optional<ErrorInfo> error;
};

// Parses `text` as one JSON document within `limits`. Never throws for bad
// input. With `recover_top_level_scalars`, a failed parse still returns, in
// `value`, an object with the root object's scalar members that precede or
// (for limit and number errors) follow the error, so a request's id can be
// echoed with the error.
BoundedParse parse_json_bounded(std::string_view text, const JsonLimits& limits,
                                bool recover_top_level_scalars = false);

// As parse_json_bounded, throwing ProtocolError on failure.
nlohmann::json parse_json_or_throw(std::string_view text, const JsonLimits& limits);

// The deepest nesting of containers in `j` (0 for a scalar), computed without
// recursion. For tests and for checks on documents built in-process.
int json_depth(const nlohmann::json& j);

}  // namespace beamcast
