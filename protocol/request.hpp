// Requests and responses of the wire protocol (PROTOCOL.md), as JSON. Pure:
// the server's sessions call these, tests and fuzzers call them directly.
#pragma once

#include <array>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/bounded_json.hpp"
#include "protocol/errors.hpp"
#include "protocol/scene.hpp"
#include "protocol/scene_json.hpp"

namespace beamcast {

inline constexpr int kProtocolVersion = 1;

// The request methods, in PROTOCOL.md's order ("## Methods"): the one list
// the server's dispatch table follows (a static_assert in
// server/request_handler.cpp), which hello's "methods", the metrics key and
// the unknown-method error read; tests compare it with PROTOCOL.md and with
// the server.
inline constexpr std::array<std::string_view, 9> kRequestMethods = {
    "hello",     "ping",       "render",       "scene.put", "scene.update",
    "scene.get", "scene.list", "scene.delete", "stats"};
const std::vector<std::string>& request_methods();
bool is_request_method(std::string_view method);
// "hello, ping, ...", for messages.
std::string request_methods_text();

struct Request {
  nlohmann::json id;  // string or integer, echoed in the response
  std::string method;
  nlohmann::json params = nlohmann::json::object();
};

// Parses one frame's JSON text within `limits` (max_json_depth,
// max_json_values: enforced while parsing, protocol/bounded_json.hpp). On
// failure throws ProtocolError (bad_json, not_finite, limit_exceeded,
// bad_request, invalid_params); `*id_out` is set to the request's id whenever it
// could be read, also when the rest of the text is refused, so the error
// response can carry it (null otherwise). An id written as an integral float
// (7.0) is read as the integer 7; a string id has at most 128 characters
// (code points).
Request parse_request(std::string_view json_text, nlohmann::json* id_out,
                      const JsonLimits& limits = {});

// hello's params.protocol: an integer, integral floats accepted (1.0), read
// as the scene format reads integers (wrong_type / out_of_range otherwise).
// Values outside int come back as -1.
int read_protocol_number(const nlohmann::json& v);

// Refuses (unknown_field, at /params/<key>) a key of a method's params that
// is not in `allowed`; every method but ping (which echoes anything) checks.
void allow_params(const nlohmann::json& params, std::initializer_list<std::string_view> allowed,
                  std::string_view method);

nlohmann::json ok_response(const nlohmann::json& id, nlohmann::json result);
nlohmann::json error_response(const nlohmann::json& id, const ErrorInfo& error);

// Re-roots an error raised while reading a nested document: "/beams/0" under
// "/params/scene" becomes "/params/scene/beams/0".
ErrorInfo with_path_prefix(ErrorInfo e, std::string_view prefix);

// `quality: "auto"` (PROTOCOL.md, "Interactive quality"): the server's accuracy
// controller picks each frame's settings from a frame-time budget.
// The preview's moving frames as a video stream (PROTOCOL.md, "Video
// preview"): the connection's encoder, kept from request to request.
struct VideoParams {
  std::string codec;                // "vp8", "vp9" or "av1"
  std::optional<int> bitrate_kbps;  // the target; none: the server's --preview-bitrate
  bool keyframe = false;            // this frame a key frame (a decoder recovering)
  int bit_depth = 8;                // the deepest samples the client decodes: 8 or 10 (AV1)
  bool bands = false;               // the client stacks a frame sent in horizontal bands (AV1)
};
inline constexpr int kMinVideoBitrateKbps = 50;
inline constexpr int kMaxVideoBitrateKbps = 50000;

struct QualityParams {
  double budget_ms = 33.0;  // frame-time budget while the camera moves
  double still_ms = 300.0;  // still this long -> a full-accuracy PNG frame
  std::string motion = "infer";  // "infer" (from successive poses), "moving", "still"
  bool jpeg = true;              // interactive frames as JPEG ("interactive_format")
  std::optional<VideoParams> video;  // moving frames as video ("video")
};

// `render` params, validated except for the scene itself (which may be stored).
struct RenderParams {
  std::optional<QualityParams> quality;  // set with "quality": "auto"
  std::optional<nlohmann::json> scene;  // inline scene, unparsed
  std::optional<std::string> scene_id;
  std::optional<std::vector<Camera>> cameras;  // replaces the scene's cameras
  std::optional<nlohmann::json> output;  // merged over the scene's "output"
  bool base64 = false;
  bool atlas = false;  // one atlas image of all frames instead of one image each
  bool stream = false;  // frames sent as their GPU batches finish (PROTOCOL.md, "Streaming")
};
RenderParams parse_render_params(const nlohmann::json& params, const SceneLimits& limits);

// A scene id: [A-Za-z0-9_.-]{1,64}; throws invalid_value / wrong_type at `path`.
std::string parse_scene_id(const nlohmann::json& params, const std::string& path);

}  // namespace beamcast
