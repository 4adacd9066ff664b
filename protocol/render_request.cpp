#include "protocol/render_request.hpp"

#include <cstdio>
#include <utility>

#include "protocol/request_cost.hpp"

namespace beamcast {
namespace {

using json = nlohmann::json;

[[noreturn]] void fail(std::string code, std::string path, std::string message) {
  throw ProtocolError(ErrorInfo{std::move(code), std::move(message), std::move(path)});
}

// The scene: parsed inline, or the stored entry (kept alive by the pointer).
void resolve_scene(const RenderLimits& limits, const FindStoredScene& find_stored,
                   ResolvedRender* r) {
  const RenderParams& rp = r->params;
  if (rp.scene) {
    r->scene = std::make_shared<const Scene>(parse_scene_at(*rp.scene, limits.load, "/params/scene"));
    return;
  }
  r->stored = find_stored ? find_stored(*rp.scene_id) : nullptr;
  if (!r->stored) fail("unknown_scene", "/params/scene_id", "no stored scene \"" + *rp.scene_id + "\"");
  r->scene = std::shared_ptr<const Scene>(r->stored, &r->stored->scene);
}

// max_request_cost (PROTOCOL.md, "Request cost"): the render's estimated
// work against the limit before anything is queued, for inline and stored
// scenes alike. The path is the dominant term's field within the request.
double check_request_cost(const ResolvedRender& r, std::int64_t max_request_cost) {
  const RenderParams& rp = r.params;
  const RequestCost cost = estimate_request_cost(*r.scene, r.cameras);
  if (cost.total <= static_cast<double>(max_request_cost)) return cost.total;
  const CostTerm* top = cost.dominant();
  const bool per_pixel = top->path == "/cameras";
  std::string path = rp.scene_id ? "/params/scene_id" : "/params/scene" + top->path;
  if (per_pixel && rp.cameras) path = "/params/cameras";
  if (per_pixel && rp.output && rp.output->contains("supersample")) {
    path = "/params/output/supersample";
  }
  char total[32];
  std::snprintf(total, sizeof total, "%.0f", cost.total);
  fail("limit_exceeded", path,
       std::string("the render's estimated cost is ") + total + " (" + cost.breakdown() +
           "), over the limit max_request_cost = " + std::to_string(max_request_cost) +
           ": fewer photons, pixels, cameras or samples (PROTOCOL.md, \"Request cost\")");
}

// The frames' sizes: each camera supersampled, and the atlas composed of them.
void check_frame_sizes(const ResolvedRender& r, const SceneLimits& limits) {
  const RenderParams& rp = r.params;
  check_supersampled_size(r.cameras, r.scene->output.supersample, limits,
                          rp.output && rp.output->contains("supersample")
                              ? "/params/output/supersample"
                              : (rp.cameras ? "/params/cameras" : "/params/scene/output/supersample"));
}

void check_atlas(const ResolvedRender& r, const SceneLimits& limits) {
  if (!r.params.atlas) return;
  // The composed image is a frame too: same limits as every camera.
  std::vector<std::pair<int, int>> sizes;
  for (const Camera& c : r.cameras) sizes.emplace_back(c.width, c.height);
  const AtlasGrid g = atlas_grid(sizes);
  check_frame_size(g.width(), g.height(), limits, "/params/atlas", "/params/atlas", "the atlas");
}

}  // namespace

Scene parse_scene_at(const json& scene_json, const SceneLoadOptions& opts, std::string_view prefix) {
  try {
    return parse_scene(scene_json, opts);
  } catch (const ProtocolError& e) {
    throw ProtocolError(with_path_prefix(e.info(), prefix));
  }
}

ResolvedRender resolve_render(const json& params, const RenderLimits& limits,
                              const FindStoredScene& find_stored) {
  const SceneLimits& scene_limits = limits.load.limits;
  ResolvedRender r;
  r.params = parse_render_params(params, scene_limits);
  const RenderParams& rp = r.params;
  resolve_scene(limits, find_stored, &r);
  if (rp.output) {
    json merged = r.scene_json().value("output", json::object());
    merged.merge_patch(*rp.output);
    auto copy = std::make_shared<Scene>(*r.scene);
    copy->output = parse_output_settings(merged, "/params/output");
    r.scene = std::move(copy);
  }
  r.cameras = rp.cameras ? *rp.cameras : r.scene->cameras;
  check_frame_sizes(r, scene_limits);
  r.cost = check_request_cost(r, limits.max_request_cost);
  check_atlas(r, scene_limits);
  // A video stream is one picture a frame.
  r.video = rp.quality ? rp.quality->video : std::nullopt;
  if (r.video && (r.cameras.size() != 1 || rp.atlas)) {
    fail("invalid_value", "/params/video", "video frames need exactly one camera and no atlas");
  }
  return r;
}

}  // namespace beamcast
