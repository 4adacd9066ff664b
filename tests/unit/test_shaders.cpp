// Every program's stages, assembled exactly as the renderer assembles them,
// must compile with the reference GLSL compiler (glslangValidator), so a broken
// shader fails here and not in a user's request.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "shaders/shader_sources.hpp"

namespace beamcast {
namespace {

struct Stage {
  std::vector<std::string_view> parts;
  const char* extension;
};

// Must match the programs built in render/passes.cpp.
const std::vector<Stage> kStages = {
    {{"common.glsl", "surface.vert"}, "vert"},
    {{"common.glsl", "surface.frag"}, "frag"},
    {{"common.glsl", "fullscreen.vert"}, "vert"},
    {{"common.glsl", "analytic_occluder.frag"}, "frag"},
    {{"common.glsl", "beam.vert"}, "vert"},
    {{"common.glsl", "beam_math.glsl", "beam.frag"}, "frag"},
    {{"common.glsl", "tonemap.frag"}, "frag"},
    // Multi-view variants (one draw, K layers).
    {{"multiview_vertex.glsl", "common.glsl", "surface.vert"}, "vert"},
    {{"multiview.glsl", "common.glsl", "surface.frag"}, "frag"},
    {{"multiview_vertex.glsl", "common.glsl", "fullscreen.vert"}, "vert"},
    {{"multiview.glsl", "common.glsl", "analytic_occluder.frag"}, "frag"},
    {{"multiview_vertex.glsl", "common.glsl", "beam.vert"}, "vert"},
    {{"multiview.glsl", "common.glsl", "beam_math.glsl", "beam.frag"}, "frag"},
    {{"multiview.glsl", "common.glsl", "tonemap.frag"}, "frag"},
};

TEST(Shaders, EveryStageCompilesWithGlslangValidator) {
  const std::string validator = GLSLANG_VALIDATOR;
  ASSERT_FALSE(validator.empty() || validator.ends_with("NOTFOUND"))
      << "glslangValidator not found at configure time (apt-get install glslang-tools)";
  const auto dir = std::filesystem::temp_directory_path() / "beamcast_shader_check";
  std::filesystem::create_directories(dir);
  for (const Stage& stage : kStages) {
    const std::string name = std::string(stage.parts.front()) + "_" +
                             std::string(stage.parts.back()) + "." + stage.extension;
    const auto file = dir / name;
    std::ofstream(file) << assemble_shader(stage.parts);
    const std::string cmd = validator + " " + file.string() + " > " + file.string() + ".log 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream log(file.string() + ".log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_EQ(rc, 0) << name << ":\n" << text;
  }
}

TEST(Shaders, AssembledSourceStartsWithVersion) {
  const std::string src = assemble_shader({"common.glsl", "beam_math.glsl", "beam.frag"});
  EXPECT_EQ(src.rfind("#version 450 core\n", 0), 0u);
  EXPECT_NE(src.find("cylinder_energy"), std::string::npos);
}

}  // namespace
}  // namespace beamcast
