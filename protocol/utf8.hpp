// UTF-8 repair for text that goes back to clients. Error messages quote client
// input (a JSON parser's "last read" bytes, clipped strings), and nlohmann::json
// refuses to serialize invalid UTF-8 (type_error 316): one stray byte from a
// client must not turn an error response into an exception.
#pragma once

#include <string>
#include <string_view>

namespace beamcast {

// True if `s` is well-formed UTF-8 (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF).
bool is_valid_utf8(std::string_view s);

// `s` with every byte that is not part of a well-formed sequence replaced by
// U+FFFD; valid input comes back unchanged.
std::string to_valid_utf8(std::string_view s);

}  // namespace beamcast
