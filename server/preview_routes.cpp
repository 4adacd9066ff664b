// The preview page and its JSON API (GET only; scenes are stored and rendered
// over the WebSocket with the ordinary requests).
#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "protocol/asset_files.hpp"
#include "protocol/errors.hpp"
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

// Example scenes: the *.json files of the assets directory (examples/) that
// the rules for scene files (resolve_asset_path) let a scene load: no link
// out of the directory, no FIFO or device.
std::vector<std::string> example_names(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() != ".json") continue;
    try {
      resolve_asset_path(dir, name, "", "example");
      names.push_back(name);
    } catch (const ProtocolError&) {
      // not servable: left out of the list
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

// One example's text, read under the same rules as a scene's files and at
// most max_message_bytes (larger could not be sent back as a request).
HttpReply example_reply(const ServerCore& core, std::string_view name) {
  const std::string file(name);
  if (!file.ends_with(".json") || file.find('/') != std::string::npos) {
    return json_reply({{"error", "no such example: names are the *.json files of /api/scenes"}},
                      404);
  }
  try {
    AssetFile in(core.config.assets_dir, file, "", "example", core.config.max_message_bytes,
                 "max_message_bytes allows");
    return HttpReply{200, "application/json", in.read_all()};
  } catch (const ProtocolError& e) {
    const std::string& code = e.info().code;
    const int status = code == "file_not_found" ? 404 : code == "limit_exceeded" ? 413 : 403;
    return json_reply({{"error", e.info().message}, {"code", code}}, status);
  }
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
    return example_reply(core, name);
  });
}

}  // namespace beamcast
