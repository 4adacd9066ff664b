// POST /v1/render and its OpenAPI document (server/http_render.hpp,
// PROTOCOL.md "HTTP render") on a real server (llvmpipe), ephemeral ports.
// Frames are small (64 x 64) except where a scene file is posted as it is.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "protocol/base64.hpp"
#include "render/image.hpp"
#include "server/http_render.hpp"
#include "tests/server/http_test_server.hpp"
#include "tests/server/test_client.hpp"

namespace beamcast {
namespace {

namespace http = boost::beast::http;
using nlohmann::json;
using test::HttpTestServer;
using test::http_request;

std::string read_text(const std::string& relative) {
  std::ifstream in(std::string(BEAMCAST_SOURCE_DIR) + "/" + relative, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

auto post(unsigned short port, const std::string& body,
          const std::vector<std::pair<std::string, std::string>>& headers = {}) {
  return http_request(port, http::verb::post, "/v1/render", body, headers);
}

json small_camera(const std::string& name, double x) {
  return {{"name", name}, {"position", {x, 3.5, 7.5}}, {"target", {0, 0.3, 0}},
          {"fov_y", 50},  {"width", 64},              {"height", 64}};
}

// The JSON error of a refused request: its status and body.
json error_of(const http::response<http::string_body>& r) {
  EXPECT_EQ(r[http::field::content_type], "application/json") << r.body();
  return json::parse(r.body()).at("error");
}

TEST(HttpRender, AScenePostedAsItIsGivesThePngOfATcpRender) {
  HttpTestServer s;
  const std::string scene = read_text("examples/paper_1set.json");
  const auto r = post(s.http_port(), scene);
  ASSERT_EQ(r.result_int(), 200) << r.body();
  EXPECT_EQ(r[http::field::content_type], "image/png");
  EXPECT_EQ(r["X-Beamcast-Camera"], "view");
  test::Conn tcp(s.port());
  const test::Reply t = tcp.call(
      {{"id", 1}, {"method", "render"}, {"params", {{"scene", json::parse(scene)}}}});
  ASSERT_TRUE(t.json.value("ok", false)) << t.json.dump();
  const std::vector<std::uint8_t> png(r.body().begin(), r.body().end());
  EXPECT_EQ(png, test::frame_bytes(t));  // the same encoder on the same pixels
  const Image img = decode_png(png);
  EXPECT_EQ(img.width, 512);
}

TEST(HttpRender, SeveralCamerasOrAcceptJsonGiveTheResultWithBase64Frames) {
  HttpTestServer s;
  // An inline scene: the in-process server has no stored demo.
  json params = {{"scene", json::parse(read_text("examples/paper_1set.json"))},
                 {"cameras", {small_camera("left", -2), small_camera("right", 2)}}};
  auto r = post(s.http_port(), params.dump());
  ASSERT_EQ(r.result_int(), 200) << r.body();
  EXPECT_EQ(r[http::field::content_type], "application/json");
  json result = json::parse(r.body());
  ASSERT_EQ(result["frames"].size(), 2u);
  for (const json& f : result["frames"]) {
    EXPECT_FALSE(f.contains("attachment"));
    const Image img = decode_png(base64_decode(f.at("data_base64").get<std::string>()));
    EXPECT_EQ(img.width, 64);
  }
  EXPECT_EQ(result["frames"][1]["camera"], "right");
  // One camera, but JSON asked for first.
  params["cameras"] = json::array({small_camera("one", 0)});
  r = post(s.http_port(), params.dump(), {{"Accept", "application/json, image/png;q=0.5"}});
  ASSERT_EQ(r.result_int(), 200) << r.body();
  EXPECT_EQ(json::parse(r.body())["frames"][0]["camera"], "one");
  // One camera, an image welcome: the PNG.
  r = post(s.http_port(), params.dump(), {{"Accept", "image/png"}});
  EXPECT_EQ(r[http::field::content_type], "image/png");
}

TEST(HttpRender, BadInputIsA400WithTheJsonPathIntoTheBody) {
  HttpTestServer s;
  json scene = json::parse(read_text("examples/paper_1set.json"));
  scene["beams"][0]["radius"] = -1;
  auto r = post(s.http_port(), scene.dump());
  EXPECT_EQ(r.result_int(), 400);
  json e = error_of(r);
  EXPECT_EQ(e["code"], "out_of_range") << e;
  EXPECT_EQ(e["path"], "/beams/0/radius") << e;  // the scene posted alone: from its root

  r = post(s.http_port(), json{{"scene_id", "demo"}, {"cameras", "view"}}.dump());
  EXPECT_EQ(r.result_int(), 400);
  EXPECT_EQ(error_of(r)["path"], "/cameras");  // render params: from their root

  r = post(s.http_port(), R"({"scene_id": "demo", "cameras": [)");
  EXPECT_EQ(r.result_int(), 400);
  EXPECT_EQ(error_of(r)["code"], "bad_json");

  r = post(s.http_port(), "[1, 2]");
  EXPECT_EQ(r.result_int(), 400);
  EXPECT_EQ(error_of(r)["code"], "invalid_params");

  r = post(s.http_port(), json{{"scene_id", "demo"}, {"stream", true}}.dump());
  EXPECT_EQ(r.result_int(), 400);
  EXPECT_EQ(error_of(r)["path"], "/stream");

  r = post(s.http_port(), json{{"scene_id", "nope"}}.dump());
  EXPECT_EQ(r.result_int(), 404);
  EXPECT_EQ(error_of(r)["code"], "unknown_scene");

  r = http_request(s.http_port(), http::verb::put, "/v1/render", "{}");
  EXPECT_EQ(r.result_int(), 405);
  EXPECT_EQ(error_of(r)["code"], "method_not_allowed");
}

TEST(HttpRender, OverTheLimitsIs413Or422) {
  ServerConfig c;
  c.max_message_bytes = 64 * 1024;
  HttpTestServer s(c);
  json params = {{"scene_id", "demo"}, {"cameras", json::array({small_camera("big", 0)})}};
  params["cameras"][0]["width"] = 5000;
  auto r = post(s.http_port(), params.dump());
  EXPECT_EQ(r.result_int(), 422);
  json e = error_of(r);
  EXPECT_EQ(e["code"], "limit_exceeded");
  EXPECT_EQ(e["path"], "/cameras/0/width") << e;

  // A body over max_message_bytes: refused when its header arrives; the
  // answer still reaches the client, which has sent the whole body.
  std::string big = json{{"scene_id", "demo"}, {"pad", std::string(100 * 1024, 'x')}}.dump();
  r = post(s.http_port(), big);
  EXPECT_EQ(r.result_int(), 413);
  EXPECT_EQ(error_of(r)["code"], "message_too_large");
}

TEST(HttpRender, WithATokenTheBearerHeaderIsNeeded) {
  ServerConfig c;
  c.token = "s3cret-token";
  HttpTestServer s(c);
  const std::string body = json{{"scene", json::parse(read_text("examples/paper_1set.json"))},
                                {"cameras", json::array({small_camera("v", 0)})}}
                               .dump();
  auto r = post(s.http_port(), body);
  EXPECT_EQ(r.result_int(), 401);
  EXPECT_EQ(error_of(r)["code"], "unauthorized");
  r = post(s.http_port(), body, {{"Authorization", "Bearer s3cret-tokem"}});
  EXPECT_EQ(r.result_int(), 401);
  r = post(s.http_port(), body, {{"Authorization", "Bearer s3cret-token"}});
  EXPECT_EQ(r.result_int(), 200) << r.body();
  EXPECT_EQ(r[http::field::content_type], "image/png");
  // The description is public.
  EXPECT_EQ(test::get(s.http_port(), "/v1/openapi.json").result_int(), 200);
}

// The OpenAPI document is the repository's file, and agrees with the server:
// its error statuses are the server's table, its RenderParams are the keys
// the render method allows, its paths are served.
TEST(HttpRender, TheOpenApiDocumentDescribesThisServer) {
  HttpTestServer s;
  const auto served = test::get(s.http_port(), "/v1/openapi.json");
  ASSERT_EQ(served.result_int(), 200);
  EXPECT_EQ(served.body(), read_text("protocol/openapi.json"));
  const json doc = json::parse(served.body());
  EXPECT_EQ(doc["openapi"].get<std::string>().substr(0, 2), "3.");

  std::set<int> documented;
  for (const auto& [status, _] : doc["paths"]["/v1/render"]["post"]["responses"].items()) {
    if (status != "200") documented.insert(std::stoi(status));
  }
  std::set<int> served_statuses;
  for (const HttpErrorStatus& row : http_error_statuses()) {
    served_statuses.insert(row.status);
    const std::string text =
        doc["paths"]["/v1/render"]["post"]["responses"][std::to_string(row.status)]["description"];
    EXPECT_NE(text.find(std::string(row.code)), std::string::npos)
        << row.code << " is not listed under " << row.status;
  }
  EXPECT_EQ(documented, served_statuses);

  // PROTOCOL.md's table ("## HTTP render": "| 400 | `bad_json`, ... |") is the same.
  std::set<std::pair<std::string, int>> in_doc, in_server;
  for (const HttpErrorStatus& row : http_error_statuses()) in_server.insert({std::string(row.code), row.status});
  std::istringstream md(read_text("protocol/PROTOCOL.md"));
  bool in_section = false;
  for (std::string line; std::getline(md, line);) {
    if (line.starts_with("## ")) in_section = line == "## HTTP render";
    if (!in_section || !line.starts_with("| ") || line.size() < 6 || !std::isdigit(line[2])) continue;
    const int status = std::stoi(line.substr(2, 3));
    const std::string codes = line.substr(8, line.rfind(" |") - 8);  // after "| 400 | "
    // Each backquoted word before a colon (a row may explain its codes after one).
    const std::string listed = codes.substr(0, codes.find(':'));
    for (std::size_t b = listed.find('`'); b != std::string::npos; b = listed.find('`', b + 1)) {
      const std::size_t e = listed.find('`', b + 1);
      in_doc.insert({listed.substr(b + 1, e - b - 1), status});
      b = e;
    }
  }
  EXPECT_EQ(in_doc, in_server);

  // The render method names its allowed keys when refusing another one.
  const auto r = post(s.http_port(), json{{"scene_id", "demo"}, {"no_such_key", 1}}.dump());
  const std::string message = error_of(r)["message"];
  const std::string allowed = message.substr(message.find("allowed fields: "));
  std::size_t listed = 0;
  for (const auto& [key, _] : doc["components"]["schemas"]["RenderParams"]["properties"].items()) {
    EXPECT_NE(allowed.find(key), std::string::npos) << key << " is not a render param: " << message;
    ++listed;
  }
  EXPECT_EQ(listed, static_cast<std::size_t>(std::count(allowed.begin(), allowed.end(), ',') + 1))
      << message;

  for (const auto& [path, ops] : doc["paths"].items()) {
    for (const auto& [verb, _] : ops.items()) {
      const auto res = http_request(s.http_port(), verb == "post" ? http::verb::post : http::verb::get,
                                    path, "{}");
      EXPECT_NE(res.result_int(), 404) << verb << " " << path;
      EXPECT_NE(res.result_int(), 405) << verb << " " << path;
    }
  }
}

}  // namespace
}  // namespace beamcast
