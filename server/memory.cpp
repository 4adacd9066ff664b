#include "server/memory.hpp"

#include <malloc.h>

namespace beamcast {

void release_large_message_memory(std::size_t message_bytes) {
  if (message_bytes >= kTrimAfterMessageBytes) malloc_trim(0);
}

}  // namespace beamcast
