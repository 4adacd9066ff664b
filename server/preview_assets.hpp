// The preview page's files (server/preview/), embedded at build time.
#pragma once

#include <vector>

namespace beamcast {

struct EmbeddedFile {
  const char* name;  // e.g. "index.html"
  const char* text;
};

const std::vector<EmbeddedFile>& preview_assets();

}  // namespace beamcast
