// Giving memory back to the system after large messages. glibc keeps freed
// heap memory for reuse, so after one 16 MiB request (and the document parsed
// from it) the server's resident size would stay high indefinitely; trimming
// after messages of at least kTrimAfterMessageBytes returns it. Smaller
// messages skip the trim: it walks the allocator's arenas.
#pragma once

#include <cstddef>

namespace beamcast {

inline constexpr std::size_t kTrimAfterMessageBytes = 1u << 20;

// Call after a message of `message_bytes` has been handled and its buffers freed.
void release_large_message_memory(std::size_t message_bytes);

}  // namespace beamcast
