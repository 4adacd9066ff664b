// main() of the test binaries that render (GL, stability, server): every
// context is a debug context (KHR_debug), every draw is validated
// (render/gl_validate.hpp), and a test fails if the driver reported an
// error or undefined behaviour while it ran, even where the code went on.
// BEAMCAST_GL_DEBUG=0 or BEAMCAST_GL_VALIDATE=0 in the environment turn
// either off (to time a test as the service runs).
#include <gtest/gtest.h>

#include <cstdlib>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "render/gl_debug.hpp"
#include "render/gl_validate.hpp"

namespace beamcast {
namespace {

// Error and undefined-behaviour messages from any thread (a server test's
// render worker too), reported against the test during which they came.
class GlDebugFailures : public ::testing::EmptyTestEventListener {
 public:
  GlDebugFailures() {
    set_gl_debug_sink([this](const GlDebugMessage& m) {
      if (m.type != "error" && m.type != "undefined behavior") return;
      std::lock_guard lock(mutex_);
      seen_.push_back(format_gl_debug_message(m));
    });
  }
  // gtest deletes its listeners at exit, perhaps before static renderers
  // free their GL objects: the sink must not outlive this object.
  ~GlDebugFailures() override { set_gl_debug_sink({}); }
  GlDebugFailures(const GlDebugFailures&) = delete;
  GlDebugFailures& operator=(const GlDebugFailures&) = delete;

  void OnTestEnd(const ::testing::TestInfo& /*info*/) override {
    std::vector<std::string> seen;
    {
      std::lock_guard lock(mutex_);
      seen = std::exchange(seen_, {});
    }
    for (const std::string& m : seen) ADD_FAILURE() << "KHR_debug: " << m;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> seen_;
};

}  // namespace
}  // namespace beamcast

int main(int argc, char** argv) {
  // Before any context exists: overwrite = 0 keeps an explicit choice.
  setenv("BEAMCAST_GL_DEBUG", "1", 0);
  setenv("BEAMCAST_GL_VALIDATE", "1", 0);
  ::testing::InitGoogleTest(&argc, argv);
  ::testing::UnitTest::GetInstance()->listeners().Append(new beamcast::GlDebugFailures);
  return RUN_ALL_TESTS();
}
