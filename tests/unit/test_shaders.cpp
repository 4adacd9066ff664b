// Every program's stages, assembled exactly as the renderer assembles them,
// must compile with the reference GLSL compiler (glslangValidator), so a broken
// shader fails here and not in a user's request.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "shaders/shader_sources.hpp"

namespace beamcast {
namespace {

// Runs glslangValidator once on every (name, source) of `files` (stage from
// the file extension of each name); returns its exit status and, per name,
// what it printed about that file. One process for all files: the validator
// prints each file's name and then its messages, and goes on after an error.
// (One process a stage took 58 CPU-s for the 167 stages; one for all, 0.6.)
std::pair<int, std::map<std::string, std::string>> validate_all(
    const std::vector<std::pair<std::string, std::string>>& files) {
  const std::string validator = GLSLANG_VALIDATOR;
  if (validator.empty() || validator.ends_with("NOTFOUND")) {
    return {-1, {{"", "glslangValidator not found at configure time (apt-get install glslang-tools)"}}};
  }
  const auto dir = std::filesystem::temp_directory_path() /
                   ("beamcast_shader_check_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::string cmd = "cd " + dir.string() + " && " + validator;
  std::map<std::string, std::string> out;
  for (const auto& [name, src] : files) {
    std::ofstream(dir / name) << src;
    cmd += " " + name;
    out[name];
  }
  cmd += " > validator.log 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream log(dir / "validator.log");
  std::string line;
  std::string* current = nullptr;
  while (std::getline(log, line)) {
    if (const auto it = out.find(line); it != out.end()) {
      current = &it->second;
    } else if (current != nullptr) {
      *current += line + "\n";
    } else {
      out[""] += line + "\n";
    }
  }
  std::filesystem::remove_all(dir);
  return {rc, out};
}

std::pair<int, std::string> validate(const std::string& name, const std::string& src) {
  auto [rc, logs] = validate_all({{name, src}});
  return {rc, logs[""] + logs[name]};
}

// Every program and variant of shaders/programs.txt (the list the renderer builds).
TEST(Shaders, EveryStageCompilesWithGlslangValidator) {
  ASSERT_GE(shader_programs().size(), 8u);
  std::vector<std::pair<std::string, std::string>> files;
  for (const ShaderProgramSpec& p : shader_programs()) {
    for (const auto& [parts, ext] : {std::pair{p.vertex, "vert"}, std::pair{p.fragment, "frag"},
                                     std::pair{p.compute, "comp"}}) {
      if (!parts.empty()) files.emplace_back(p.name + "." + ext, assemble_shader(parts));
    }
  }
  const auto [rc, logs] = validate_all(files);
  EXPECT_EQ(rc, 0) << (logs.count("") ? logs.at("") : "");
  for (const auto& [name, log] : logs) {
    EXPECT_EQ(log.find("ERROR"), std::string::npos) << name << ":\n" << log;
  }
}

// The manifest names every GLSL file of shaders/ (an unlisted file would be
// neither embedded nor compiled by the test above).
TEST(Shaders, ManifestNamesEveryShaderFile) {
  std::set<std::string> listed;
  for (const ShaderProgramSpec& p : shader_programs()) {
    listed.insert(p.vertex.begin(), p.vertex.end());
    listed.insert(p.fragment.begin(), p.fragment.end());
    listed.insert(p.compute.begin(), p.compute.end());
  }
  std::set<std::string> on_disk;
  for (const auto& e : std::filesystem::directory_iterator(BEAMCAST_SOURCE_DIR "/shaders")) {
    const auto ext = e.path().extension();
    if (ext == ".glsl" || ext == ".vert" || ext == ".frag" || ext == ".comp") on_disk.insert(e.path().filename());
  }
  EXPECT_EQ(listed, on_disk);
  EXPECT_EQ(shader_program("beam_multiview").fragment.front(), "multiview.glsl");
  EXPECT_EQ(shader_program("beam").fragment.back(), "beam.frag");
}

// A compute program has its comp stage alone, and variants prepend their
// prelude to it as to the other stages.
TEST(Shaders, ComputeProgramsHaveTheirStageAlone) {
  const ShaderProgramSpec& plan = shader_program("slim_patch_plan");
  EXPECT_TRUE(plan.vertex.empty());
  EXPECT_TRUE(plan.fragment.empty());
  ASSERT_FALSE(plan.compute.empty());
  EXPECT_EQ(plan.compute.back(), "slim_patch_plan.comp");
  const ShaderProgramSpec& multi = shader_program("slim_patch_plan_multiview");
  ASSERT_EQ(multi.compute.size(), plan.compute.size() + 1);
  EXPECT_EQ(multi.compute.front(), "multiview.glsl");
  EXPECT_TRUE(multi.vertex.empty());
  for (const ShaderProgramSpec& p : shader_programs()) {
    EXPECT_TRUE(p.compute.empty() || (p.vertex.empty() && p.fragment.empty())) << p.name;
  }
}

// A compile error names the file and its own line, in the log and the listing.
TEST(Shaders, CompileErrorNamesFileAndLine) {
  const std::string src = assemble_shader_text(
      {{"common.glsl", shader_text("common.glsl")},
       {"broken.frag", "out vec4 o;\nvoid main() {\n  o = vec4(undefined_name);\n}"}});
  const auto [rc, log] = validate("broken.frag", src);
  ASSERT_NE(rc, 0) << log;
  // glslang: "ERROR: 1:3: 'undefined_name' : undeclared identifier".
  const std::string annotated = annotate_shader_log(log, src);
  EXPECT_NE(annotated.find("ERROR: broken.frag:3:"), std::string::npos) << annotated;
  // Mesa's and NVIDIA's forms.
  // Mesa's form (it reports source string 0 for every file) and NVIDIA's.
  EXPECT_EQ(annotate_shader_log("0:100003(7): error: x\n0(12) : error C1008: y\n", src),
            "broken.frag:3(7): error: x\ncommon.glsl(12) : error C1008: y\n");
  const std::string listing = numbered_shader_source(src);
  EXPECT_NE(listing.find("broken.frag:   3 |   o = vec4(undefined_name);\n"), std::string::npos)
      << listing;
  EXPECT_NE(listing.find("common.glsl:   1 | "), std::string::npos) << listing;
  EXPECT_EQ(listing.find("beamcast-source"), std::string::npos) << listing;
}

TEST(Shaders, AssembledSourceStartsWithVersion) {
  const std::string src = assemble_shader({"common.glsl", "beam_math.glsl", "beam.frag"});
  EXPECT_EQ(src.rfind("#version 450 core\n", 0), 0u);
  EXPECT_NE(src.find("cylinder_energy"), std::string::npos);
}

}  // namespace
}  // namespace beamcast
