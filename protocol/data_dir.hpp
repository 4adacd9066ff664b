// Where binaries find their data files (examples/, bench/'s plot scripts)
// without source-tree paths baked in at build time.
#pragma once

#include <filesystem>
#include <string_view>

namespace beamcast {

// The directory `sub` ("examples", "bench") of the first root that has it:
// $BEAMCAST_DATA_DIR, <executable's dir>/../share/beamcast (an installed
// tree), <executable's dir>/../.. (build/bin/ in a source checkout). Empty if
// none has it; options (--assets, --scene) override what callers get here.
std::filesystem::path find_data_dir(std::string_view sub);

// The directory of the running executable (/proc/self/exe); empty if unknown.
std::filesystem::path executable_dir();

}  // namespace beamcast
