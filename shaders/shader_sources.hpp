// The GLSL sources of shaders/, embedded at build time.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace beamcast {

struct ShaderSource {
  const char* name;  // file name, e.g. "beam.frag"
  const char* text;
};

const std::vector<ShaderSource>& shader_sources();

// Text of one embedded file; aborts with a message if it does not exist
// (a missing shader is a build error, not a user error).
std::string_view shader_text(std::string_view name);

// A complete stage source: the "#version" line, then each file of `parts` in
// order (e.g. {"common.glsl", "beam.frag"}). Line directives keep compiler
// messages pointing at the right file and line.
std::string assemble_shader(const std::vector<std::string_view>& parts);

}  // namespace beamcast
