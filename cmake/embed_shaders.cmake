# Turns shader files into a C++ source with one string per file.
# Usage: cmake -DOUT=<file.cpp> -DFILES="a.frag;b.vert" -P embed_shaders.cmake
set(body "// Generated from shaders/ by cmake/embed_shaders.cmake; do not edit.\n")
string(APPEND body "#include \"shaders/shader_sources.hpp\"\n\nnamespace beamcast {\n\n")
string(APPEND body "const std::vector<ShaderSource>& shader_sources() {\n")
string(APPEND body "  static const std::vector<ShaderSource> kSources = {\n")
foreach(f IN LISTS FILES)
  get_filename_component(name "${f}" NAME)
  file(READ "${f}" text)
  # Raw string literal; the delimiter cannot occur in GLSL.
  string(APPEND body "    {\"${name}\", R\"glsl_src(${text})glsl_src\"},\n")
endforeach()
string(APPEND body "  };\n  return kSources;\n}\n\n}  // namespace beamcast\n")
file(WRITE "${OUT}.tmp" "${body}")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
