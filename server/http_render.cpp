#include "server/http_render.hpp"

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "protocol/base64.hpp"
#include "protocol/bounded_json.hpp"
#include "protocol/request.hpp"
#include "server/connection.hpp"
#include "server/http_server.hpp"
#include "server/openapi_document.hpp"
#include "server/request_handler.hpp"
#include "server/server_core.hpp"

namespace beamcast {
namespace {

using json = nlohmann::json;

// PROTOCOL.md, "HTTP render": the status of each error code.
constexpr HttpErrorStatus kStatuses[] = {
    {"bad_json", 400},           {"bad_request", 400},        {"invalid_params", 400},
    {"missing_field", 400},      {"wrong_type", 400},         {"unknown_field", 400},
    {"invalid_value", 400},      {"out_of_range", 400},       {"not_finite", 400},
    {"degenerate_capsule", 400}, {"duplicate_name", 400},     {"conflicting_fields", 400},
    {"forbidden_path", 400},     {"file_not_found", 400},     {"bad_mesh", 400},
    {"bad_slim", 400},           {"unauthorized", 401},       {"unknown_scene", 404},
    {"method_not_allowed", 405}, {"message_too_large", 413},  {"limit_exceeded", 422},
    {"internal", 500},           {"busy", 503},               {"shutting_down", 503},
    {"deadline_exceeded", 504},
};

// Error paths point into the body: a scene posted alone is /params/scene in
// the request the handler sees, render params are /params.
std::string body_path(const std::string& path, bool scene_body) {
  for (const std::string_view prefix : {std::string_view("/params/scene"), std::string_view("/params")}) {
    if (prefix == "/params/scene" && !scene_body) continue;
    if (path == prefix) return "";
    if (path.starts_with(prefix) && path[prefix.size()] == '/') return path.substr(prefix.size());
  }
  return path;
}

HttpReply error_reply(const ErrorInfo& e, bool scene_body) {
  const json body = {{"error",
                      {{"code", e.code}, {"message", e.message}, {"path", body_path(e.path, scene_body)}}}};
  HttpReply r{http_status_for_error(e.code), "application/json",
              body.dump(-1, ' ', false, json::error_handler_t::replace), {}};
  if (r.status == 503) r.headers.emplace_back("Retry-After", "1");
  return r;
}

// One frame with its attachment: the image itself, with the result's numbers
// in headers. Otherwise (several frames, "encoding": "base64", or the client
// accepts only JSON) the result as JSON, each attachment as data_base64.
HttpReply ok_reply(json result, const std::vector<std::uint8_t>& binary, bool want_json) {
  json& frames = result["frames"];
  if (!want_json && frames.size() == 1 && frames[0].contains("attachment")) {
    const json& f = frames[0];
    const std::size_t off = f["attachment"]["offset"], len = f["attachment"]["length"];
    HttpReply r{200, f.value("format", "png") == "jpeg" ? "image/jpeg" : "image/png",
                std::string(binary.begin() + static_cast<std::ptrdiff_t>(off),
                            binary.begin() + static_cast<std::ptrdiff_t>(off + len)),
                {}};
    r.headers.emplace_back("X-Beamcast-Camera", f.value("camera", ""));
    if (const auto t = result.find("timings"); t != result.end() && t->contains("server_ms")) {
      r.headers.emplace_back("X-Beamcast-Server-Ms", (*t)["server_ms"].dump());
    }
    return r;
  }
  for (json& f : frames) {
    if (!f.contains("attachment")) continue;
    const std::size_t off = f["attachment"]["offset"], len = f["attachment"]["length"];
    f["data_base64"] = base64_encode(std::span(binary).subspan(off, len));
    f.erase("attachment");
  }
  return {200, "application/json", result.dump(), {}};
}

// The render's client: one per POST. It answers the HTTP request once, with
// the first response the handler sends (a streamed render is refused before).
class HttpRenderConnection : public Connection {
 public:
  HttpRenderConnection(ServerCore& core, bool want_json, std::function<void(HttpReply)> reply)
      : Connection(1), core_(core), want_json_(want_json), reply_(std::move(reply)) {}
  // A render dropped without an answer (the server stopping) still answers.
  ~HttpRenderConnection() override {
    answer(error_reply({"shutting_down", "the render was dropped: the server is stopping", ""},
                       scene_body_));
  }

  void send(const json& response, std::vector<std::uint8_t> binary) override {
    if (!response.value("ok", false)) {
      const json& e = response["error"];
      return answer(error_reply({e.value("code", "internal"), e.value("message", ""),
                                 e.value("path", "")},
                                scene_body_));
    }
    answer(ok_reply(response["result"], binary, want_json_));
  }
  void send_error(const json& /*id*/, const ErrorInfo& error) override {
    core_.stats.count_error(error.code);
    answer(error_reply(error, scene_body_));
  }
  // Whether the body was a scene alone (error paths are then relative to it).
  void set_scene_body(bool scene_body) { scene_body_ = scene_body; }
  void refuse(const ErrorInfo& error) { send_error(nullptr, error); }

  void close() override {
    mark_gone();
    answer(error_reply({"shutting_down", "the server is stopping", ""}, scene_body_));
  }

 private:
  void answer(HttpReply r) {
    if (answered_.exchange(true)) return;
    reply_(std::move(r));
  }
  ServerCore& core_;
  bool scene_body_ = false;  // set before the request is handed on
  const bool want_json_;
  std::function<void(HttpReply)> reply_;
  std::atomic<bool> answered_{false};
};

// A client that lists image types but not application/json... or lists
// application/json first, gets JSON for a single frame too.
bool wants_json(std::string_view accept) {
  const auto j = accept.find("application/json");
  if (j == std::string_view::npos) return false;
  const auto img = accept.find("image/");
  return img == std::string_view::npos || j < img;
}

void render(ServerCore& core, HttpPost post, std::function<void(HttpReply)> reply) {
  const auto arrived = std::chrono::steady_clock::now();
  // The body is params (or a scene) that sits two levels down in a TCP
  // request: it may nest that much less deep.
  JsonLimits limits = core.config.json_limits;
  limits.max_depth = std::max(1, limits.max_depth - 2);
  auto connection =
      std::make_shared<HttpRenderConnection>(core, wants_json(post.accept), std::move(reply));
  // The route's gate (http_request_authorized) checked the bearer token.
  connection->set_authenticated();
  // Parsing is what costs memory: reserved first, as on TCP.
  MemoryBudget::Reservation reserved;
  if (!reserve_request_memory(core, *connection, post.body.size(), &reserved)) return;
  auto held = std::make_shared<MemoryBudget::Reservation>(std::move(reserved));
  BoundedParse parsed = parse_json_bounded(post.body, limits);
  post.body.clear();
  post.body.shrink_to_fit();
  if (parsed.error) return connection->refuse(*parsed.error);
  if (!parsed.value.is_object()) {
    return connection->refuse({"invalid_params",
                   "the body must be a JSON object: a scene, or render params with \"scene\" or "
                   "\"scene_id\"",
                   ""});
  }
  const bool scene_body = !parsed.value.contains("scene") && !parsed.value.contains("scene_id");
  connection->set_scene_body(scene_body);
  if (const auto s = parsed.value.find("stream"); s != parsed.value.end() && *s == true) {
    return connection->refuse({"invalid_value",
                   "\"stream\": true needs the TCP or WebSocket protocol; over HTTP a render is "
                   "answered once",
                   "/params/stream"});
  }
  Request req;
  req.id = 0;
  req.method = "render";
  if (scene_body) {
    req.params = {{"scene", std::move(parsed.value)}};
  } else {
    req.params = std::move(parsed.value);
  }
  handle_request(core, connection, std::move(req), arrived, [held] { held->release(); });
}

}  // namespace

int http_status_for_error(std::string_view code) {
  for (const HttpErrorStatus& s : kStatuses) {
    if (s.code == code) return s.status;
  }
  return 500;
}

std::span<const HttpErrorStatus> http_error_statuses() { return kStatuses; }

std::string_view openapi_document() { return openapi_documents().at(0).text; }

void register_http_render_routes(HttpServer& http, ServerCore& core) {
  http.add_post("/v1/render", [&core](HttpPost post, std::function<void(HttpReply)> reply) {
    render(core, std::move(post), std::move(reply));
  });
  const std::string doc(openapi_document());
  http.add_get("/v1/openapi.json", [doc] { return HttpReply{200, "application/json", doc, {}}; });
}

}  // namespace beamcast
