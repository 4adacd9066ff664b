#include "server/memory.hpp"

#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <boost/asio/steady_timer.hpp>

namespace beamcast {

std::uint64_t resident_bytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long long pages = 0, resident = 0;
  const int n = std::fscanf(f, "%llu %llu", &pages, &resident);
  std::fclose(f);
  if (n != 2) return 0;
  return resident * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
}

void release_large_message_memory(std::size_t message_bytes) {
  if (message_bytes >= kTrimAfterMessageBytes) malloc_trim(0);
}

std::size_t trim_free_heap(std::size_t threshold) {
  const struct mallinfo2 info = mallinfo2();
  if (info.fordblks > threshold) malloc_trim(0);
  return info.fordblks;
}

namespace {

// The pending wait holds the timer, as a session's handlers hold the session.
void arm_trim(std::shared_ptr<boost::asio::steady_timer> timer, const std::atomic<bool>& stop) {
  timer->expires_after(std::chrono::milliseconds(kTrimPeriodMs));
  timer->async_wait([timer, &stop](const boost::system::error_code& ec) {
    if (ec || stop.load()) return;
    trim_free_heap();
    arm_trim(timer, stop);
  });
}

}  // namespace

void start_heap_trimmer(boost::asio::io_context& io, const std::atomic<bool>& stop) {
  arm_trim(std::make_shared<boost::asio::steady_timer>(io), stop);
}

void configure_allocator() {
  // glibc raises its mmap threshold to the size of each large block freed
  // (up to 32 MiB), so after one 13 MB request the next ones are served from
  // the heap, whose pages malloc_trim did not give back: 24.5 MiB stayed
  // resident after one such request. A fixed threshold keeps blocks of 4 MiB
  // and more (message buffers, parse vectors, frames) in their own mappings,
  // returned on free: +0.6 MiB (docs/performance.md, "Memory after large
  // requests"). 1 MiB measured the same; 4 MiB leaves frames of a 1024 x 1024
  // render on the heap.
  mallopt(M_MMAP_THRESHOLD, 4 << 20);
}

MemoryBudget::Reservation& MemoryBudget::Reservation::operator=(Reservation&& o) noexcept {
  if (this != &o) {
    release();
    budget_ = o.budget_;
    bytes_ = o.bytes_;
    o.budget_ = nullptr;
  }
  return *this;
}

void MemoryBudget::Reservation::release() {
  if (budget_) budget_->used_.fetch_sub(bytes_);
  budget_ = nullptr;
}

bool MemoryBudget::try_reserve(std::uint64_t message_bytes, Reservation* out, ErrorInfo* error) {
  const std::uint64_t need = estimate(message_bytes);
  const std::string what = "a message of " + std::to_string(message_bytes) +
                           " bytes is estimated to need " + std::to_string(need) +
                           " bytes of memory (" + std::to_string(kParseCostFactor) +
                           " per byte) ";
  if (need > limit_) {
    *error = {"limit_exceeded",
              what + "over max_request_memory_bytes = " + std::to_string(limit_), ""};
    return false;
  }
  std::uint64_t used = used_.load();
  do {
    if (used + need > limit_) {
      *error = {"busy",
                what + "and requests being handled hold " + std::to_string(used) +
                    " of max_request_memory_bytes = " + std::to_string(limit_) +
                    ": retry later",
                ""};
      return false;
    }
  } while (!used_.compare_exchange_weak(used, used + need));
  *out = Reservation(this, need);
  return true;
}

}  // namespace beamcast
