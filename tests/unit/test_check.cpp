// BEAMCAST_CHECK / BEAMCAST_DCHECK (protocol/check.hpp): invariant failures
// are InternalError (never ProtocolError), name the condition and the place,
// and evaluate the message only on failure; DCHECK is off with NDEBUG.
#include <gtest/gtest.h>

#include <string>

#include "protocol/check.hpp"
#include "protocol/errors.hpp"
#include "render/atlas.hpp"

namespace beamcast {
namespace {

TEST(Check, PassingCheckEvaluatesNoMessage) {
  int messages = 0;
  auto msg = [&] {
    ++messages;
    return std::string("never");
  };
  BEAMCAST_CHECK(1 + 1 == 2, msg());
  EXPECT_EQ(messages, 0);
}

TEST(Check, FailingCheckThrowsInternalErrorWithPlace) {
  int line = 0;
  try {
    const int views = 3;
    line = __LINE__ + 1;
    BEAMCAST_CHECK(views == 4, "views: " + std::to_string(views));
    FAIL() << "no throw";
  } catch (const ProtocolError&) {
    FAIL() << "an invariant is not a client error";
  } catch (const InternalError& e) {
    EXPECT_STREQ(e.what(),
                 ("internal error: views: 3 (check views == 4 failed at unit/test_check.cpp:" +
                  std::to_string(line) + ")")
                     .c_str());
  }
}

TEST(Check, DcheckOnlyInDebugBuilds) {
  int evaluated = 0;
  auto fails = [&] {
    ++evaluated;
    return false;
  };
#ifdef NDEBUG
  BEAMCAST_DCHECK(fails(), "off with NDEBUG");
  EXPECT_EQ(evaluated, 0);
#else
  EXPECT_THROW(BEAMCAST_DCHECK(fails(), "on in Debug builds"), InternalError);
  EXPECT_EQ(evaluated, 1);
#endif
}

// A real site: make_atlas's callers never pass an empty list.
TEST(Check, AtlasOfNoFramesIsAnInternalError) { EXPECT_THROW(make_atlas({}), InternalError); }

}  // namespace
}  // namespace beamcast
