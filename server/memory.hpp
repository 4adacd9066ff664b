// Memory that requests cost the server.
//
// MemoryBudget: every request reserves an estimate of what it will cost
// (message bytes x kParseCostFactor) against one server-wide budget,
// max_request_memory_bytes, before it is read into a buffer (TCP: when its
// header arrives) or parsed (WebSocket: Beast has read it), and releases it
// once its parsed state is freed. Past the budget the request is answered
// `busy`; a request whose estimate alone exceeds it gets `limit_exceeded`.
//
// Giving memory back to the system after large messages: glibc keeps freed
// heap memory for reuse, so after one 16 MiB request (and the document parsed
// from it) the server's resident size would stay high indefinitely; trimming
// after messages of at least kTrimAfterMessageBytes returns it. Smaller
// messages skip the trim: it walks the allocator's arenas.
#pragma once

#include <atomic>

#include <boost/asio/io_context.hpp>
#include <cstddef>
#include <cstdint>

#include "protocol/errors.hpp"

namespace beamcast {

inline constexpr std::size_t kTrimAfterMessageBytes = 1u << 20;

// Heap bytes per message byte, an upper bound over the JSON shapes a request
// can take, measured with mallinfo2 on nlohmann::json as parse_json_bounded
// builds it (tests/server/test_request_memory.cpp checks it): the costliest
// shape, an array of empty objects, costs 27 per byte with 1 M elements
// ("{}," is 3 bytes: a 64-byte map allocation, 21 per byte, plus a 16-byte
// slot, 5.3 per byte); others measured 25 (members holding empty objects),
// 22 (empty strings), 8 (small integers). The slot buffer can be twice the
// element count (+5.3: 32) and, while it grows, briefly exists twice (+5.3
// more: 37.6); 40 covers that.
inline constexpr std::uint64_t kParseCostFactor = 40;

// Call after a message of `message_bytes` has been handled and its buffers freed.
void release_large_message_memory(std::size_t message_bytes);

// Work whose memory is freed on other threads, later (a render's scene with a
// mesh or SLIM file, the GL passes' buffers) leaves free heap that no message
// trim sees: the server calls trim_free_heap every kTrimPeriodMs, which trims
// once the allocator's arenas hold more than kTrimWhenFreeBytes free (mallinfo2,
// a walk of the bins: microseconds). Measured after 4 renders of a 405 000-
// triangle mesh file: 66 MiB above the baseline stayed, 30 after a trim
// (docs/performance.md, "Memory after large requests").
inline constexpr int kTrimPeriodMs = 1000;
inline constexpr std::size_t kTrimWhenFreeBytes = 8u << 20;
// Trims if more than `threshold` bytes are free; returns the free bytes seen.
std::size_t trim_free_heap(std::size_t threshold = kTrimWhenFreeBytes);
// Calls trim_free_heap on `io` every kTrimPeriodMs until `stop` is set or
// `io` stops.
void start_heap_trimmer(boost::asio::io_context& io, const std::atomic<bool>& stop);

// Caches that outlive a render (each renderer's photon maps, volume textures,
// frame targets) hold hundreds of MiB after a large request: fog maps of
// 6 M events are 330 MB, and one renderer may keep 256 MiB of maps. A render
// worker that has rendered nothing for kIdleReleaseMs gives them back
// (FrameRenderer::release_idle_memory), keeping kIdlePhotonCacheBytes of the
// most recently used photon maps, so a preview of a lit scene that pauses
// does not trace again; then it trims the heap. Repeated renders never wait
// that long between slices, so they keep every cache
// (docs/performance.md, "Memory after large requests").
inline constexpr int kIdleReleaseMs = 2000;
inline constexpr std::size_t kIdlePhotonCacheBytes = 16u << 20;
// What the caches do not hold, llvmpipe may: after fog renders of millions of
// volume photons (drawn as quads) its context kept 150-220 MiB (heaptrack:
// live blocks allocated by swrast_dri.so during the draws) that no GL delete
// frees. So after the release, if the process is still more than
// kRebuildWhenIdleAboveBytes above its leanest idle size (the lowest RSS
// seen after an idle release, at most its size at start plus
// kRebuildWhenIdleAboveBytes; after a replacement, the size it left), the
// idle worker replaces its renderer with a
// new one (a new GL context, ~0.1-0.3 s of CPU; the next render compiles its
// shader variants again). Between small renders RSS stays under it (a
// small render of each kind adds up to 45 MiB of shader variants and
// tables over the server's size at start), so a normal session never pays it.
// Not under ASan, whose quarantine is most of the resident size.
inline constexpr std::uint64_t kRebuildWhenIdleAboveBytes = 48ull << 20;
// The process's resident size (/proc/self/statm), 0 if unknown.
std::uint64_t resident_bytes();

// Sets the allocator up for a server that handles large messages (Server's
// constructor calls it; process-wide): a fixed mmap threshold, see memory.cpp.
void configure_allocator();

class MemoryBudget {
 public:
  explicit MemoryBudget(std::uint64_t limit_bytes) : limit_(limit_bytes) {}
  MemoryBudget(const MemoryBudget&) = delete;
  MemoryBudget& operator=(const MemoryBudget&) = delete;

  // Holds bytes of the budget until destroyed (or moved from).
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& o) noexcept : budget_(o.budget_), bytes_(o.bytes_) { o.budget_ = nullptr; }
    Reservation& operator=(Reservation&& o) noexcept;
    ~Reservation() { release(); }
    void release();
    std::uint64_t bytes() const { return budget_ ? bytes_ : 0; }

   private:
    friend class MemoryBudget;
    Reservation(MemoryBudget* b, std::uint64_t n) : budget_(b), bytes_(n) {}
    MemoryBudget* budget_ = nullptr;
    std::uint64_t bytes_ = 0;
  };

  // The estimated cost of a message of `message_bytes`.
  static std::uint64_t estimate(std::uint64_t message_bytes) { return message_bytes * kParseCostFactor; }
  // Reserves estimate(message_bytes), or returns the error for the client:
  // limit_exceeded (the estimate alone is over the limit) or busy (other
  // requests hold the rest), both naming max_request_memory_bytes.
  [[nodiscard]] bool try_reserve(std::uint64_t message_bytes, Reservation* out, ErrorInfo* error);
  std::uint64_t in_use() const { return used_.load(); }
  std::uint64_t limit() const { return limit_; }

 private:
  const std::uint64_t limit_;
  std::atomic<std::uint64_t> used_{0};
};

}  // namespace beamcast
