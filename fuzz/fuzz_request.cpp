// libFuzzer target: one request's JSON text through the same validation the
// server runs (parse_request, then per method resolve_render, parse_scene,
// parse_scene_id), ending with the response serialized the way
// Session::send does it. Any exception other than ProtocolError is a finding:
// the server would answer "internal" (or worse) instead of a clear error.
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/render_request.hpp"
#include "protocol/request.hpp"
#include "protocol/scene_json.hpp"

using beamcast::ProtocolError;
using json = nlohmann::json;

namespace {

json handle(const beamcast::Request& req, const beamcast::SceneLoadOptions& opts) {
  const json& params = req.params;
  if (req.method == "render") {
    // Every scene_id names the base scene, as if stored.
    static const auto stored = [&opts] {
      auto s = std::make_shared<beamcast::StoredScene>();
      s->json = beamcast::fuzz::base_scene_json();
      s->scene = beamcast::parse_scene(s->json, opts);
      return std::shared_ptr<const beamcast::StoredScene>(std::move(s));
    }();
    // max_request_cost: the server's default (server/config.hpp).
    const beamcast::ResolvedRender r = beamcast::resolve_render(
        params, {opts, 120000}, [](const std::string&) { return stored; });
    return {{"frames", r.cameras.size()}};
  }
  if (req.method == "scene.put" || req.method == "scene.update") {
    const std::string sid = beamcast::parse_scene_id(params, "/params/scene_id");
    const char* key = req.method == "scene.put" ? "scene" : "patch";
    auto it = params.find(key);
    if (it == params.end() || !it->is_object()) {
      throw ProtocolError({"wrong_type", std::string(key) + " must be an object",
                           std::string("/params/") + key});
    }
    json doc = *it;
    if (req.method == "scene.update") {
      doc = beamcast::fuzz::base_scene_json();
      doc.merge_patch(*it);
    }
    beamcast::Scene scene = beamcast::parse_scene(doc, opts);
    return {{"scene_id", sid}, {"bytes", doc.dump().size()}, {"beams", scene.beams.size()}};
  }
  if (req.method == "scene.delete") return {{"deleted", beamcast::parse_scene_id(params, "/p")}};
  return {{"echo", params}};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const beamcast::SceneLoadOptions opts = beamcast::fuzz::load_options();
  json id;
  json response;
  try {
    const beamcast::Request req = beamcast::parse_request(text, &id);
    // Nothing deeper than max_json_depth gets past the parser (issue 19).
    FUZZ_CHECK(beamcast::json_depth(req.params) < beamcast::JsonLimits{}.max_depth);
    response = beamcast::ok_response(id, handle(req, opts));
  } catch (const ProtocolError& e) {
    beamcast::fuzz::check_error(e.info());
    // An echoed id is always one the protocol allows.
    FUZZ_CHECK(id.is_null() || id.is_string() || id.is_number_integer());
    response = beamcast::error_response(id, e.info());
  }
  // Session::send serializes with the strict UTF-8 handler: it must not throw.
  beamcast::fuzz::serialize(response);
  return 0;
}
