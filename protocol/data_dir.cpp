#include "protocol/data_dir.hpp"

#include <cstdlib>
#include <system_error>
#include <vector>

namespace beamcast {

std::filesystem::path executable_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

std::filesystem::path find_data_dir(std::string_view sub) {
  std::vector<std::filesystem::path> roots;
  if (const char* env = std::getenv("BEAMCAST_DATA_DIR"); env && *env) roots.emplace_back(env);
  if (const auto exe = executable_dir(); !exe.empty()) {
    roots.push_back(exe / ".." / "share" / "beamcast");
    roots.push_back(exe / ".." / "..");
  }
  for (const auto& root : roots) {
    std::error_code ec;
    const auto dir = root / sub;
    if (std::filesystem::is_directory(dir, ec)) return std::filesystem::weakly_canonical(dir, ec);
  }
  return {};
}

}  // namespace beamcast
