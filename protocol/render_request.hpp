// A `render` request resolved (PROTOCOL.md, "render"): its params and the
// scene they name turned, in one call, into what the server renders: the
// parsed scene with the request's output settings merged, the cameras, the
// estimated cost, every limit checked. Pure: no server types, no sockets, no
// GL; parse_scene reads only the asset files the scene names, below
// the assets directory. Bad input throws ProtocolError with the JSON path of
// the field within the request ("/params/...").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/request.hpp"
#include "protocol/scene.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

// A scene stored under an id (scene.put / scene.update), as validated.
struct StoredScene {
  nlohmann::json json;  // as validated (scene.update patches this)
  Scene scene;
  std::uint64_t bytes = 0;  // size of the JSON text: what the store's limit counts
};

// The stored scene of an id; null if none. The caller's store (the server's
// SceneStore, a test's map): the resolver calls it only for a valid scene_id.
using FindStoredScene = std::function<std::shared_ptr<const StoredScene>(const std::string& id)>;

// What a render may ask for (PROTOCOL.md, "Limits").
struct RenderLimits {
  SceneLoadOptions load;  // assets directory and scene limits (parse_scene's)
  std::int64_t max_request_cost = 0;  // PROTOCOL.md, "Request cost"
};

struct ResolvedRender {
  RenderParams params;                        // validated; params.scene is the inline scene's JSON
  std::shared_ptr<const StoredScene> stored;  // the entry, for a scene_id (kept alive)
  std::shared_ptr<const Scene> scene;         // parsed, params.output merged over its output
  std::vector<Camera> cameras;                // params.cameras, or the scene's
  double cost = 0.0;                          // estimate_request_cost's total
  std::optional<VideoParams> video;           // params.quality->video

  // The scene's JSON: inline, or the stored entry's.
  const nlohmann::json& scene_json() const { return params.scene ? *params.scene : stored->json; }
  // Where the scene sits in the request (error paths of the render itself).
  const char* scene_path() const { return params.scene ? "/params/scene" : "/params/scene_id"; }
};

// Parses and checks a render's params and scene. Errors, in this order:
// the params (parse_render_params), the inline scene (at /params/scene),
// unknown_scene (/params/scene_id), params.output, the supersampled frame
// size, max_request_cost, the atlas' size, and video (one camera, no atlas).
ResolvedRender resolve_render(const nlohmann::json& params, const RenderLimits& limits,
                              const FindStoredScene& find_stored);

// parse_scene of a scene that sits at `prefix` within the request: its
// errors' paths begin with `prefix`.
Scene parse_scene_at(const nlohmann::json& scene_json, const SceneLoadOptions& opts,
                     std::string_view prefix);

}  // namespace beamcast
