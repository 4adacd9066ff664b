// The preview page and its JSON API (GET only; scenes are stored and rendered
// over the WebSocket with the ordinary requests).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "server/http_server.hpp"
#include "server/preview_assets.hpp"
#include "server/server_core.hpp"

namespace beamcast {
namespace {

const char* content_type(std::string_view name) {
  if (name.ends_with(".html")) return "text/html; charset=utf-8";
  if (name.ends_with(".js")) return "text/javascript; charset=utf-8";
  if (name.ends_with(".css")) return "text/css; charset=utf-8";
  return "text/plain; charset=utf-8";
}

HttpReply json_reply(const nlohmann::json& j, int status = 200) {
  return {status, "application/json", j.dump()};
}

// Example scenes: the *.json files of the assets directory (examples/).
std::vector<std::string> example_names(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (e.is_regular_file() && e.path().extension() == ".json") {
      names.push_back(e.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

void register_preview_routes(HttpServer& http, ServerCore& core) {
  for (const EmbeddedFile& f : preview_assets()) {
    const std::string name = f.name;
    HttpReply reply{200, content_type(name), f.text};
    http.add_get("/" + name, [reply] { return reply; });
    if (name == "index.html") http.add_get("/", [reply] { return reply; });
  }
  // Browsers ask for it; no icon, and no 404 in their consoles.
  http.add_get("/favicon.ico", [] { return HttpReply{204, "image/x-icon", ""}; });
  http.add_get("/api/scenes", [&core] {
    return json_reply({{"stored", core.scenes.ids()},
                       {"examples", example_names(core.config.assets_dir)}});
  });
  http.add_get_prefix("/api/scenes/", [&core](std::string_view id) {
    auto stored = core.scenes.get(std::string(id));
    if (!stored) return json_reply({{"error", "no stored scene"}}, 404);
    return json_reply(stored->json);
  });
  http.add_get_prefix("/api/examples/", [&core](std::string_view name) {
    // Only names listed by /api/scenes: no path can leave the directory.
    const auto names = example_names(core.config.assets_dir);
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      return json_reply({{"error", "no such example"}}, 404);
    }
    std::ifstream in(core.config.assets_dir / std::string(name), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return HttpReply{200, "application/json", text.str()};
  });
}

}  // namespace beamcast
