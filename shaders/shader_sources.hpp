// The GLSL sources of shaders/, embedded at build time, and the program
// manifest (programs.txt) that says which files make each program.
#pragma once

#include <string>
#include <string_view>
#include <utility>
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

// One program of shaders/programs.txt: the files of each stage, in order.
struct ShaderProgramSpec {
  std::string name;  // e.g. "beam"; a variant's is "beam_multiview"
  std::vector<std::string_view> vertex;
  std::vector<std::string_view> fragment;
  std::vector<std::string_view> compute;  // a compute program has this stage only
};

// Every program of the manifest, then every program again in each variant
// (the variant's file prepended to both stages), in manifest order.
const std::vector<ShaderProgramSpec>& shader_programs();

// The program called `name` (e.g. "tonemap_multiview"); aborts if there is none.
const ShaderProgramSpec& shader_program(std::string_view name);

// A complete stage source: the "#version" line, then each file of `parts` in
// order (e.g. {"common.glsl", "beam.frag"}). Each file starts with a marker
// comment naming it and a "#line" directive, so compiler messages identify
// the file and its line, and the helpers below map them back to names.
std::string assemble_shader(const std::vector<std::string_view>& parts);

// The same from (file name, text) pairs: for sources not embedded (tests).
std::string assemble_shader_text(
    const std::vector<std::pair<std::string_view, std::string_view>>& parts);

// An assembled source listed for an error message: each line prefixed with
// its file name and line number within that file ("beam.frag:  12 | ...").
std::string numbered_shader_source(std::string_view assembled);

// A compiler's info log with its source references replaced by file names
// and lines within the file: Mesa's "0:200012(3)", glslang's
// "ERROR: 2:200007:" and NVIDIA's "2(200007)" become "beam.frag:12(3)",
// "ERROR: beam.frag:7:", "beam.frag(7)" when beam.frag is file 2.
std::string annotate_shader_log(std::string_view log, std::string_view assembled);

}  // namespace beamcast
