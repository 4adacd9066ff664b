// Client-facing errors: a stable code, a message for people, and the JSON path
// (RFC 6901 pointer, e.g. "/beams/3/radius") of the field that caused it.
#pragma once

#include <stdexcept>
#include <string>

namespace beamcast {

struct ErrorInfo {
  std::string code;     // e.g. "invalid_value", "missing_field", "limit_exceeded"
  std::string message;  // one sentence, names the value and the rule it broke
  std::string path;     // JSON pointer of the offending field ("" for the whole message)
};

class ProtocolError : public std::runtime_error {
 public:
  explicit ProtocolError(ErrorInfo info)
      : std::runtime_error(info.path.empty() ? info.message : info.path + ": " + info.message),
        info_(std::move(info)) {}
  const ErrorInfo& info() const { return info_; }

 private:
  ErrorInfo info_;
};

}  // namespace beamcast
