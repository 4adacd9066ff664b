#include "protocol/request.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "protocol/json_reader.hpp"

#include "protocol/utf8.hpp"

namespace beamcast {

const std::vector<std::string>& request_methods() {
  static const std::vector<std::string> kMethods(kRequestMethods.begin(), kRequestMethods.end());
  return kMethods;
}

bool is_request_method(std::string_view method) {
  const auto& m = request_methods();
  return std::find(m.begin(), m.end(), method) != m.end();
}

std::string request_methods_text() {
  std::string out;
  for (const auto& m : request_methods()) out += (out.empty() ? "" : ", ") + m;
  return out;
}
namespace {
[[noreturn]] void fail(std::string code, std::string path, std::string message) {
  throw ProtocolError(ErrorInfo{std::move(code), std::move(message), std::move(path)});
}

bool valid_id_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}
}  // namespace

namespace {

// Number of Unicode code points in valid UTF-8 (continuation bytes not counted).
std::size_t code_points(std::string_view s) {
  std::size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

// An id may be written as an integral float (7.0), as the scene format accepts
// integers (docs/scene-format.md); it is read as 7. Unlike scene integers, any
// int64 is a valid id.
bool integral_number(const nlohmann::json& v, std::int64_t* out) {
  if (v.is_number_integer()) {
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) {
      return false;
    }
    *out = v.get<std::int64_t>();
    return true;
  }
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  if (!(d >= -9.2e18 && d <= 9.2e18) || d != std::floor(d)) return false;
  *out = static_cast<std::int64_t>(d);
  return true;
}

// The request's id if it is acceptable, else null.
nlohmann::json read_id(const nlohmann::json& v, std::string* problem) {
  if (v.is_string()) {
    if (code_points(v.get_ref<const std::string&>()) > 128) {
      *problem = "id must be at most 128 characters";
      return nullptr;
    }
    return v;
  }
  std::int64_t i = 0;
  if (integral_number(v, &i)) return i;
  *problem = "id must be a string or an integer";
  return nullptr;
}

}  // namespace

Request parse_request(std::string_view text, nlohmann::json* id_out, const JsonLimits& limits) {
  *id_out = nullptr;
  BoundedParse parsed = parse_json_bounded(text, limits, /*recover_top_level_scalars=*/true);
  nlohmann::json& j = parsed.value;
  if (parsed.error) {
    // Echo the id when it could be read, so a pipelining client can match the error.
    std::string ignored;
    if (auto id = j.find("id"); id != j.end()) *id_out = read_id(*id, &ignored);
    throw ProtocolError(std::move(*parsed.error));
  }
  if (!j.is_object()) fail("bad_json", "", "a request must be a JSON object");
  Request r;
  auto id = j.find("id");
  if (id == j.end()) fail("bad_request", "/id", "request has no \"id\"");
  std::string problem;
  r.id = read_id(*id, &problem);
  if (r.id.is_null()) fail("bad_request", "/id", problem);
  *id_out = r.id;
  auto method = j.find("method");
  if (method == j.end()) fail("bad_request", "/method", "request has no \"method\"");
  if (!method->is_string()) fail("bad_request", "/method", "method must be a string");
  r.method = method->get<std::string>();
  if (auto p = j.find("params"); p != j.end()) {
    if (!p->is_object()) fail("invalid_params", "/params", "params must be an object");
    r.params = std::move(*p);
  }
  for (const auto& [key, value] : j.items()) {
    (void)value;
    if (key != "id" && key != "method" && key != "params") {
      fail("bad_request", json_read::child_path("", key),
           "unknown request field \"" + to_valid_utf8(key.substr(0, 64)) +
               "\" (a request has id, method and params)");
    }
  }
  return r;
}

int read_protocol_number(const nlohmann::json& v) {
  const std::int64_t i = json_read::read_integer(json_read::Node{&v, "/params/protocol"});
  return i < INT32_MIN || i > INT32_MAX ? -1 : static_cast<int>(i);
}

void allow_params(const nlohmann::json& params, std::initializer_list<std::string_view> allowed,
                  std::string_view method) {
  json_read::ObjectReader(json_read::Node{&params, "/params"}, std::string(method) + " params")
      .allow_only(allowed);
}

nlohmann::json ok_response(const nlohmann::json& id, nlohmann::json result) {
  return {{"id", id}, {"ok", true}, {"result", std::move(result)}};
}

nlohmann::json error_response(const nlohmann::json& id, const ErrorInfo& e) {
  // Messages and paths quote client bytes (parser excerpts, clipped strings,
  // object keys); repair them so the response always serializes.
  return {{"id", id},
          {"ok", false},
          {"error",
           {{"code", to_valid_utf8(e.code)},
            {"message", to_valid_utf8(e.message)},
            {"path", to_valid_utf8(e.path)}}}};
}

ErrorInfo with_path_prefix(ErrorInfo e, std::string_view prefix) {
  e.path = std::string(prefix) + e.path;
  return e;
}

std::string parse_scene_id(const nlohmann::json& params, const std::string& path) {
  auto it = params.find("scene_id");
  if (it == params.end()) fail("missing_field", path, "scene_id is required");
  const std::string id = json_read::read_string(json_read::Node{&*it, path});
  bool ok = !id.empty() && id.size() <= 64;
  for (char c : id) ok = ok && valid_id_char(c);
  if (!ok) fail("invalid_value", path, "scene_id must match [A-Za-z0-9_.-]{1,64}");
  return id;
}

namespace {

// One of `allowed`; anything else, a non-string included, is invalid_value
// (what these params have always answered), listing the choices.
std::string read_choice(const json_read::Node& n, std::initializer_list<std::string_view> allowed) {
  std::string list;
  std::size_t i = 0;
  for (std::string_view a : allowed) {
    if (n.json().is_string() && n.json().get_ref<const std::string&>() == a) return std::string(a);
    list += (i == 0 ? "" : i + 1 == allowed.size() ? " or " : ", ") + ('"' + std::string(a) + '"');
    ++i;
  }
  fail("invalid_value", n.path, n.name() + " must be " + list);
}

// The value at `n`, which must be an object (wrong_type naming `what`).
const nlohmann::json& object_at(const json_read::Node& n, std::string_view what) {
  const json_read::ObjectReader is_object(n, what);
  return n.json();
}

// "video": {"codec": "vp8"|"vp9"|"av1", "bitrate_kbps": N, "keyframe": bool,
// "bit_depth": 8|10, "bands": bool}.
VideoParams parse_video_params(const json_read::Node& n) {
  static constexpr std::string_view kKeys[] = {"codec", "bitrate_kbps", "keyframe", "bit_depth", "bands"};
  const json_read::ObjectReader r(n, "video");
  r.allow_only(kKeys);
  VideoParams v;
  v.codec = read_choice(r.required("codec"), {"vp8", "vp9", "av1"});
  if (auto b = r.optional("bitrate_kbps")) {
    v.bitrate_kbps = static_cast<int>(json_read::check_closed(
        *b, static_cast<double>(json_read::read_integer(*b)), kMinVideoBitrateKbps,
        kMaxVideoBitrateKbps));
  }
  if (auto k = r.optional("keyframe")) v.keyframe = json_read::read_bool(*k);
  if (auto d = r.optional("bit_depth")) {
    const auto bits = json_read::read_integer(*d);
    if (bits != 8 && bits != 10) fail("invalid_value", d->path, d->name() + " must be 8 or 10");
    v.bit_depth = static_cast<int>(bits);
  }
  if (auto b = r.optional("bands")) v.bands = json_read::read_bool(*b);
  return v;
}

}  // namespace

RenderParams parse_render_params(const nlohmann::json& params, const SceneLimits& limits) {
  using json_read::check_closed, json_read::Node, json_read::ObjectReader, json_read::read_array,
      json_read::read_bool, json_read::read_number;
  static constexpr std::string_view kKeys[] = {
      "scene",   "scene_id",  "cameras",  "output", "encoding",          "atlas",
      "quality", "budget_ms", "still_ms", "motion", "interactive_format", "stream", "video"};
  const ObjectReader r(Node{&params, "/params"}, "render params");
  r.allow_only(kKeys);
  RenderParams rp;
  const auto quality = r.optional("quality");
  const bool automatic = quality && read_choice(*quality, {"auto", "full"}) == "auto";
  for (const char* key : {"budget_ms", "still_ms", "motion", "interactive_format", "video"}) {
    if (r.optional(key) && !automatic) {
      fail("invalid_value", r.path_of(key),
           std::string(key) + " applies only with \"quality\": \"auto\"");
    }
  }
  if (automatic) {
    QualityParams qp;
    if (auto n = r.optional("budget_ms")) {
      qp.budget_ms = check_closed(*n, read_number(*n), 1.0, 10000.0);
    }
    if (auto n = r.optional("still_ms")) {
      qp.still_ms = check_closed(*n, read_number(*n), 0.0, 60000.0);
    }
    if (auto n = r.optional("motion")) qp.motion = read_choice(*n, {"infer", "moving", "still"});
    if (auto n = r.optional("interactive_format")) {
      qp.jpeg = read_choice(*n, {"jpeg", "png"}) == "jpeg";
    }
    if (auto v = r.optional("video")) qp.video = parse_video_params(*v);
    rp.quality = qp;
  }
  const auto scene = r.optional("scene");
  const auto scene_id = r.optional("scene_id");
  if (scene.has_value() == scene_id.has_value()) {
    fail(scene ? "conflicting_fields" : "missing_field", "/params",
         "render needs exactly one of \"scene\" (inline) and \"scene_id\" (stored)");
  }
  if (scene) {
    rp.scene = object_at(*scene, "scene");  // parsed by the caller
  } else {
    rp.scene_id = parse_scene_id(params, scene_id->path);
  }
  if (auto c = r.optional("cameras")) {
    if (read_array(*c).empty()) fail("invalid_value", c->path, "cameras must not be empty");
    rp.cameras = parse_camera_list(c->json(), c->path, limits);
  }
  if (auto o = r.optional("output")) {
    rp.output = object_at(*o, "output");  // merged over the scene's by the caller
  }
  if (auto a = r.optional("atlas")) rp.atlas = read_bool(*a);
  if (auto st = r.optional("stream")) {
    rp.stream = read_bool(*st);
    // An atlas is one image of every frame: nothing to send before the end.
    if (rp.stream && rp.atlas) {
      fail("conflicting_fields", st->path, "\"stream\": true cannot be combined with \"atlas\": true");
    }
  }
  if (auto e = r.optional("encoding")) {
    rp.base64 = read_choice(*e, {"binary", "base64"}) == "base64";
  }
  return rp;
}

}  // namespace beamcast
