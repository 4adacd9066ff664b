#include "protocol/request.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "protocol/json_reader.hpp"

#include "protocol/utf8.hpp"

namespace beamcast {

const std::vector<std::string>& request_methods() {
  static const std::vector<std::string> kMethods = {
      "hello", "ping", "render", "scene.put", "scene.update", "scene.delete", "stats"};
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
  if (!it->is_string()) fail("wrong_type", path, "scene_id must be a string");
  const auto& id = it->get_ref<const std::string&>();
  bool ok = !id.empty() && id.size() <= 64;
  for (char c : id) ok = ok && valid_id_char(c);
  if (!ok) fail("invalid_value", path, "scene_id must match [A-Za-z0-9_.-]{1,64}");
  return id;
}

RenderParams parse_render_params(const nlohmann::json& params, const SceneLimits& limits) {
  RenderParams rp;
  allow_params(params,
               {"scene", "scene_id", "cameras", "output", "encoding", "atlas", "quality", "budget_ms",
                "still_ms", "motion", "interactive_format"},
               "render");
  bool automatic = false;
  if (auto q = params.find("quality"); q != params.end()) {
    if (!q->is_string() || (*q != "auto" && *q != "full")) {
      fail("invalid_value", "/params/quality", "quality must be \"auto\" or \"full\"");
    }
    automatic = *q == "auto";
  }
  for (const char* key : {"budget_ms", "still_ms", "motion", "interactive_format"}) {
    if (params.contains(key) && !automatic) {
      fail("invalid_value", std::string("/params/") + key,
           std::string(key) + " applies only with \"quality\": \"auto\"");
    }
  }
  if (automatic) {
    QualityParams qp;
    auto number = [&](const char* key, double lo, double hi, double* out) {
      auto it = params.find(key);
      if (it == params.end()) return;
      const std::string path = std::string("/params/") + key;
      if (!it->is_number()) fail("wrong_type", path, std::string(key) + " must be a number");
      const double v = it->get<double>();
      if (!(v >= lo && v <= hi)) {
        char range[64];
        std::snprintf(range, sizeof range, " must be in [%g, %g]", lo, hi);
        fail("out_of_range", path, std::string(key) + range);
      }
      *out = v;
    };
    number("budget_ms", 1.0, 10000.0, &qp.budget_ms);
    number("still_ms", 0.0, 60000.0, &qp.still_ms);
    if (auto m = params.find("motion"); m != params.end()) {
      if (!m->is_string() || (*m != "infer" && *m != "moving" && *m != "still")) {
        fail("invalid_value", "/params/motion", "motion must be \"infer\", \"moving\" or \"still\"");
      }
      qp.motion = m->get<std::string>();
    }
    if (auto f = params.find("interactive_format"); f != params.end()) {
      if (!f->is_string() || (*f != "jpeg" && *f != "png")) {
        fail("invalid_value", "/params/interactive_format",
             "interactive_format must be \"jpeg\" or \"png\"");
      }
      qp.jpeg = *f == "jpeg";
    }
    rp.quality = qp;
  }
  const bool has_scene = params.contains("scene");
  const bool has_id = params.contains("scene_id");
  if (has_scene == has_id) {
    fail(has_scene ? "conflicting_fields" : "missing_field", "/params",
         "render needs exactly one of \"scene\" (inline) and \"scene_id\" (stored)");
  }
  if (has_scene) {
    if (!params["scene"].is_object()) fail("wrong_type", "/params/scene", "scene must be an object");
    rp.scene = params["scene"];
  } else {
    rp.scene_id = parse_scene_id(params, "/params/scene_id");
  }
  if (auto c = params.find("cameras"); c != params.end()) {
    if (!c->is_array()) fail("wrong_type", "/params/cameras", "cameras must be an array");
    if (c->empty()) fail("invalid_value", "/params/cameras", "cameras must not be empty");
    std::vector<Camera> cams = parse_camera_list(*c, "/params/cameras", limits);
    rp.cameras = std::move(cams);
  }
  if (auto o = params.find("output"); o != params.end()) {
    if (!o->is_object()) fail("wrong_type", "/params/output", "output must be an object");
    rp.output = *o;
  }
  if (auto a = params.find("atlas"); a != params.end()) {
    if (!a->is_boolean()) fail("wrong_type", "/params/atlas", "atlas must be true or false");
    rp.atlas = a->get<bool>();
  }
  if (auto e = params.find("encoding"); e != params.end()) {
    if (!e->is_string() || (*e != "binary" && *e != "base64")) {
      fail("invalid_value", "/params/encoding", "encoding must be \"binary\" or \"base64\"");
    }
    rp.base64 = *e == "base64";
  }
  return rp;
}

}  // namespace beamcast
