#include "cli/frame_choice.hpp"

#include <cstdio>

#include "protocol/errors.hpp"

namespace beamcast::cli {
namespace {

constexpr int kMaxSide = 16384;  // the server's own limits apply on top (max_width ...)

// The frame name of camera `i`: its name, else camera_<i> (as frames are named).
template <typename NameOf>
std::vector<std::size_t> chosen(const std::vector<std::string>& want, std::size_t count,
                                const NameOf& name_of) {
  std::vector<std::size_t> out;
  for (const std::string& w : want) {
    bool found = false;
    for (std::size_t i = 0; i < count && !found; ++i) {
      if (name_of(i) == w) {
        out.push_back(i);
        found = true;
      }
    }
    if (!found) {
      std::string names;
      for (std::size_t i = 0; i < count; ++i) names += (i ? ", " : "") + name_of(i);
      throw ProtocolError(ErrorInfo{"unknown_camera",
                                    "no camera \"" + w + "\" in the scene; its cameras: " + names,
                                    "--camera"});
    }
  }
  return out;
}

}  // namespace

void add_frame_choice_options(CLI::App* cmd, FrameChoice* choice) {
  cmd->add_option("--camera", choice->cameras,
                  "Render only this camera of the scene (by name, or camera_<index> for an "
                  "unnamed one); repeat for several");
  cmd->add_option_function<std::string>(
         "--size",
         [choice](const std::string& s) {
           int w = 0, h = 0;
           char x = 0, extra = 0;
           if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 ||
               h < 1 || w > kMaxSide || h > kMaxSide) {
             throw CLI::ValidationError("--size", "expected WIDTHxHEIGHT (1 to 16384), got " + s);
           }
           choice->width = w;
           choice->height = h;
         },
         "Frame size WIDTHxHEIGHT for every camera (default: each camera's own)");
}

void apply_frame_choice(const FrameChoice& choice, std::vector<Camera>* cameras) {
  if (!choice.cameras.empty()) {
    const auto name_of = [&](std::size_t i) {
      const std::string& n = (*cameras)[i].name;
      return n.empty() ? "camera_" + std::to_string(i) : n;
    };
    std::vector<Camera> picked;
    for (std::size_t i : chosen(choice.cameras, cameras->size(), name_of)) {
      picked.push_back((*cameras)[i]);
      if (picked.back().name.empty()) picked.back().name = name_of(i);
    }
    *cameras = std::move(picked);
  }
  if (choice.width > 0) {
    for (Camera& c : *cameras) {
      c.width = choice.width;
      c.height = choice.height;
    }
  }
}

void apply_frame_choice(const FrameChoice& choice, nlohmann::json* scene) {
  if (!scene->is_object() || !scene->contains("cameras") || !(*scene)["cameras"].is_array()) return;
  nlohmann::json& cams = (*scene)["cameras"];
  if (!choice.cameras.empty()) {
    const auto name_of = [&](std::size_t i) {
      const auto& c = cams[i];
      return c.is_object() && c.contains("name") && c["name"].is_string()
                 ? c["name"].get<std::string>()
                 : "camera_" + std::to_string(i);
    };
    nlohmann::json picked = nlohmann::json::array();
    for (std::size_t i : chosen(choice.cameras, cams.size(), name_of)) {
      picked.push_back(cams[i]);
      if (picked.back().is_object()) picked.back()["name"] = name_of(i);
    }
    cams = std::move(picked);
  }
  if (choice.width > 0) {
    for (auto& c : cams) {
      if (!c.is_object()) continue;
      c["width"] = choice.width;
      c["height"] = choice.height;
    }
  }
}

}  // namespace beamcast::cli
