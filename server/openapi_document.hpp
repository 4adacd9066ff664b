// protocol/openapi.json, embedded at build time (server/CMakeLists.txt).
#pragma once

#include <vector>

#include "server/preview_assets.hpp"  // EmbeddedFile

namespace beamcast {

const std::vector<EmbeddedFile>& openapi_documents();

}  // namespace beamcast
