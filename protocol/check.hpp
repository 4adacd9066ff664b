// Checks of the program's own invariants, distinct from client errors.
//
// A client's bad input is a ProtocolError (errors.hpp): a code, a message and
// the JSON path, answered to that client. A broken invariant is a bug here:
// BEAMCAST_CHECK(cond, msg) throws InternalError naming the condition, file
// and line. It throws rather than aborts so that, in the server, the request
// that hit the bug gets an `internal` error response (and a log line) while
// other clients carry on; tools and tests let it end the program loudly.
// BEAMCAST_DCHECK is the same in Debug builds (the ASan stage of CI) and
// compiles to nothing, evaluating neither argument, with NDEBUG: for checks
// too costly for a release hot path.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace beamcast {

class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

[[noreturn]] inline void check_failed(const char* cond, std::string_view file, int line,
                                      const std::string& msg) {
  // The path from the source tree's top folder on ("render/image.cpp").
  if (const auto last = file.rfind('/'); last != std::string_view::npos && last > 0) {
    if (const auto cut = file.rfind('/', last - 1); cut != std::string_view::npos) {
      file.remove_prefix(cut + 1);
    }
  }
  throw InternalError("internal error: " + msg + " (check " + cond + " failed at " +
                      std::string(file) + ":" + std::to_string(line) + ")");
}

}  // namespace beamcast

// `msg` (anything a std::string can be made of) is evaluated only on failure.
#define BEAMCAST_CHECK(cond, msg)                                            \
  do {                                                                       \
    if (!(cond)) [[unlikely]] {                                              \
      ::beamcast::check_failed(#cond, __FILE__, __LINE__, std::string(msg)); \
    }                                                                        \
  } while (false)

#ifdef NDEBUG
#define BEAMCAST_DCHECK(cond, msg) \
  do {                             \
    if (false) {                   \
      static_cast<void>(cond);     \
      static_cast<void>(msg);      \
    }                              \
  } while (false)
#else
#define BEAMCAST_DCHECK(cond, msg) BEAMCAST_CHECK(cond, msg)
#endif
