// After a GL error a render worker discards its renderer and creates a new
// one (issue 12, item 6): the failed request is answered `internal`, the next
// ones are served with frames byte-identical to a server that never failed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json occluder_scene() {
  std::ifstream in(std::filesystem::path(BEAMCAST_SOURCE_DIR) / "examples" / "beam_occluder.json");
  json scene = json::parse(in);
  scene["cameras"][0]["width"] = 96;
  scene["cameras"][0]["height"] = 64;
  return scene;
}

json render_req(const json& id) {
  return {{"id", id}, {"method", "render"}, {"params", {{"scene", occluder_scene()}}}};
}

using test::frame_bytes;

TEST(RendererRebuild, GlErrorAnswersInternalAndTheNextFramesMatchAFreshServer) {
  std::vector<std::uint8_t> reference;
  {
    test::LocalServer fresh;
    test::Conn c(fresh.port());
    const test::Reply r = c.call(render_req("ref"));
    ASSERT_TRUE(r.json.value("ok", false)) << r.json;
    reference = frame_bytes(r);
  }

  test::LocalServer s;  // one render worker
  test::Conn c(s.port());
  s.core().renders->fail_next_render_for_test();
  // Pipelined: the failing render and two after it, plus a ping on another connection.
  c.send(render_req("failed"));
  c.send(render_req("after1"));
  c.send(render_req("after2"));
  test::Conn other(s.port());
  EXPECT_TRUE(other.call({{"id", "p"}, {"method", "ping"}}).json.value("ok", false));

  int answered = 0;
  for (int i = 0; i < 3; ++i) {
    const test::Reply r = c.recv();
    if (r.json["id"] == "failed") {
      ASSERT_FALSE(r.json.value("ok", true)) << r.json;
      EXPECT_EQ(r.json["error"]["code"], "internal");
      EXPECT_NE(r.json["error"]["message"].get<std::string>().find("injected test failure"),
                std::string::npos)
          << r.json;
    } else {
      ASSERT_TRUE(r.json.value("ok", false)) << r.json;
      EXPECT_EQ(frame_bytes(r), reference) << "frame of " << r.json["id"];
    }
    ++answered;
  }
  EXPECT_EQ(answered, 3);

  const test::Reply st = c.call({{"id", "st"}, {"method", "stats"}});
  EXPECT_EQ(st.json["result"]["renderer_rebuilds"], 1) << st.json;
  const test::Reply prom =
      c.call({{"id", "pm"}, {"method", "stats"}, {"params", {{"format", "prometheus"}}}});
  EXPECT_NE(prom.json["result"]["text"].get<std::string>().find("beamcast_renderer_rebuilds_total 1\n"),
            std::string::npos);
}

TEST(RendererRebuild, WithoutAnInjectedFailureNoRebuild) {
  test::LocalServer s;
  test::Conn c(s.port());
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(c.call(render_req(i)).json.value("ok", false));
  }
  EXPECT_EQ(c.call({{"id", "st"}, {"method", "stats"}}).json["result"]["renderer_rebuilds"], 0);
}

}  // namespace
}  // namespace beamcast
