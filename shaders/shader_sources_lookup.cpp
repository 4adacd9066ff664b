#include <cstdio>
#include <cstdlib>
#include <map>
#include <regex>
#include <sstream>

#include "shaders/shader_sources.hpp"

namespace beamcast {

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "beamcast: internal error: %s\n", what.c_str());
  std::abort();
}

// Marks the start of each file in an assembled source; followed by
// "#line N*kLineStride+1 N". The source-string number N is what glslang and
// NVIDIA report; Mesa reports 0 for every file but keeps the line, so the
// line number alone also identifies the file: N = line / kLineStride.
constexpr std::string_view kMarker = "// beamcast-source ";
constexpr int kLineStride = 100000;

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

std::vector<ShaderProgramSpec> parse_manifest() {
  // Texts are embedded, so the views into them live as long as the program.
  const std::string_view text = shader_text("programs.txt");
  std::vector<ShaderProgramSpec> programs;
  std::vector<std::pair<std::string_view, std::string_view>> variants;  // name, file
  std::size_t pos = 0;
  for (int n = 1; pos < text.size(); ++n) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const auto w = words(text.substr(pos, end - pos));
    pos = end + 1;
    if (w.empty() || w[0].front() == '#') continue;
    const std::string where = "shaders/programs.txt:" + std::to_string(n);
    if (w[0] == "variant" && w.size() == 3) {
      variants.emplace_back(w[1], w[2]);
      continue;
    }
    if (w[0] != "program" || w.size() < 4 || (w[2] != "vert" && w[2] != "frag" && w[2] != "comp")) {
      fail(where +
           ": expected 'program <name> <vert|frag|comp> <file>...' or 'variant <name> <file>'");
    }
    ShaderProgramSpec* p = nullptr;
    for (auto& q : programs) {
      if (q.name == w[1]) p = &q;
    }
    if (!p) p = &programs.emplace_back(ShaderProgramSpec{std::string(w[1]), {}, {}, {}});
    auto& stage = w[2] == "vert" ? p->vertex : w[2] == "frag" ? p->fragment : p->compute;
    if (!stage.empty()) fail(where + ": second " + std::string(w[2]) + " stage of " + p->name);
    for (std::size_t i = 3; i < w.size(); ++i) {
      shader_text(w[i]);  // aborts if the file is not embedded
      stage.push_back(w[i]);
    }
  }
  const std::size_t base = programs.size();
  for (std::size_t i = 0; i < base; ++i) {
    const ShaderProgramSpec& p = programs[i];
    const bool graphics = !p.vertex.empty() && !p.fragment.empty() && p.compute.empty();
    const bool compute = p.vertex.empty() && p.fragment.empty() && !p.compute.empty();
    if (!graphics && !compute) {
      fail("shaders/programs.txt: program " + p.name +
           " needs a vert and a frag stage, or a comp stage alone");
    }
  }
  for (const auto& [variant, file] : variants) {
    for (std::size_t i = 0; i < base; ++i) {
      ShaderProgramSpec v = programs[i];
      v.name += "_" + std::string(variant);
      for (auto* stage : {&v.vertex, &v.fragment, &v.compute}) {
        if (!stage->empty()) stage->insert(stage->begin(), file);
      }
      programs.push_back(std::move(v));
    }
  }
  return programs;
}

// Source-string number -> file name, from the markers of an assembled source.
std::map<int, std::string> file_names(std::string_view assembled) {
  std::map<int, std::string> names;
  std::size_t pos = 0;
  while ((pos = assembled.find(kMarker, pos)) != std::string_view::npos) {
    pos += kMarker.size();
    const std::size_t end = std::min(assembled.find('\n', pos), assembled.size());
    const auto w = words(assembled.substr(pos, end - pos));  // "N:" "name"
    if (w.size() == 2 && w[0].size() > 1 && w[0].back() == ':') {
      names[std::atoi(std::string(w[0]).c_str())] = std::string(w[1]);
    }
  }
  return names;
}

}  // namespace

std::string_view shader_text(std::string_view name) {
  for (const auto& s : shader_sources()) {
    if (name == s.name) return s.text;
  }
  fail("no embedded shader named '" + std::string(name) + "'");
}

const std::vector<ShaderProgramSpec>& shader_programs() {
  static const std::vector<ShaderProgramSpec> kPrograms = parse_manifest();
  return kPrograms;
}

const ShaderProgramSpec& shader_program(std::string_view name) {
  for (const auto& p : shader_programs()) {
    if (p.name == name) return p;
  }
  fail("no shader program named '" + std::string(name) + "' in shaders/programs.txt");
}

std::string assemble_shader_text(
    const std::vector<std::pair<std::string_view, std::string_view>>& parts) {
  std::string out = "#version 450 core\n";
  int file_index = 0;
  for (const auto& [name, text] : parts) {
    const std::string n = std::to_string(file_index);
    out += std::string(kMarker) + n + ": " + std::string(name) + "\n#line " +
           std::to_string(file_index * kLineStride + 1) + " " + n + "\n";
    ++file_index;
    out += text;
    out += "\n";
  }
  return out;
}

std::string assemble_shader(const std::vector<std::string_view>& parts) {
  std::vector<std::pair<std::string_view, std::string_view>> texts;
  for (auto part : parts) texts.emplace_back(part, shader_text(part));
  return assemble_shader_text(texts);
}

std::string numbered_shader_source(std::string_view assembled) {
  const auto names = file_names(assembled);
  static const std::regex kLine(R"(^\s*#\s*line\s+(\d+)\s+(\d+)\s*$)");
  std::ostringstream out;
  std::string file = "(assembled)";
  int line_no = 1;
  std::istringstream in{std::string(assembled)};
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (line.starts_with(kMarker)) continue;
    if (std::regex_match(line, m, kLine)) {
      // The next line is line m[1] of source string m[2].
      const int first = std::stoi(m[1]);
      line_no = first % kLineStride;
      const auto it = names.find(first / kLineStride);
      file = it != names.end() ? it->second : "source " + m[2].str();
      continue;
    }
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s:%4d | ", file.c_str(), line_no++);
    out << buf << line << '\n';
  }
  return out.str();
}

std::string annotate_shader_log(std::string_view log, std::string_view assembled) {
  const auto names = file_names(assembled);
  // Optional severity prefix (glslang), source-string number, ':' or '(' , line.
  static const std::regex kRef(R"(^((?:ERROR|WARNING|INFO): )?(\d+)([:(])(\d+))");
  std::ostringstream out;
  std::istringstream in{std::string(log)};
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, kRef)) {
      const int at = std::stoi(m[4]);
      const auto it = names.find(at / kLineStride);
      if (it != names.end()) {
        line = m[1].str() + it->second + m[3].str() + std::to_string(at % kLineStride) +
               m.suffix().str();
      }
    }
    out << line << '\n';
  }
  return out.str();
}

}  // namespace beamcast
