#include "server/threads.hpp"

#include <cerrno>
#include <system_error>
#include <utility>

namespace beamcast {
namespace {

void* trampoline(void* arg) {
  std::unique_ptr<std::function<void()>> fn(static_cast<std::function<void()>*>(arg));
  (*fn)();
  return nullptr;
}

}  // namespace

SizedThread::SizedThread(std::function<void()> fn, std::size_t stack_bytes) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  int rc = pthread_attr_setstacksize(&attr, stack_bytes);
  auto owned = std::make_unique<std::function<void()>>(std::move(fn));
  if (rc == 0) rc = pthread_create(&thread_, &attr, trampoline, owned.get());
  pthread_attr_destroy(&attr);
  if (rc != 0) throw std::system_error(rc, std::generic_category(), "pthread_create");
  owned.release();  // the thread owns it now
  joinable_ = true;
}

SizedThread::SizedThread(SizedThread&& other) noexcept
    : thread_(other.thread_), joinable_(std::exchange(other.joinable_, false)) {}

SizedThread::~SizedThread() {
  if (joinable_) join();
}

void SizedThread::join() {
  if (!joinable_) return;
  pthread_join(thread_, nullptr);
  joinable_ = false;
}

}  // namespace beamcast
