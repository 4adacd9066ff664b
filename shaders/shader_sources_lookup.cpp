#include <cstdio>
#include <cstdlib>

#include "shaders/shader_sources.hpp"

namespace beamcast {

std::string_view shader_text(std::string_view name) {
  for (const auto& s : shader_sources()) {
    if (name == s.name) return s.text;
  }
  std::fprintf(stderr, "beamcast: internal error: no embedded shader named '%.*s'\n",
               static_cast<int>(name.size()), name.data());
  std::abort();
}

std::string assemble_shader(const std::vector<std::string_view>& parts) {
  std::string out = "#version 450 core\n";
  int file_index = 0;
  for (auto part : parts) {
    // "#line 1 N": the source-string number N identifies the part in error logs.
    out += "#line 1 " + std::to_string(file_index++) + "\n";
    out += shader_text(part);
    out += "\n";
  }
  return out;
}

}  // namespace beamcast
