// The server's render path without GL (tests/server/fake_renderer.hpp):
// frames come back as sent by the renderer, a GL error makes the worker build
// a new renderer, any other exception does not.
#include <gtest/gtest.h>

#include <memory>

#include "render/image.hpp"
#include "tests/server/fake_renderer.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

json render_req(int id) {
  return {{"id", id}, {"method", "render"}, {"params", {{"scene", test::tiny_scene(24)}}}};
}

// The frame's PNG decoded: the fake's flat grey.
void expect_fake_frame(const test::Reply& r) {
  ASSERT_TRUE(r.json.value("ok", false)) << r.json;
  const Image img = decode_png(test::frame_bytes(r));
  ASSERT_EQ(img.width, 24);
  ASSERT_EQ(img.height, 24);
  for (std::uint16_t v : img.rgb) ASSERT_EQ(v, test::FakeRendererControl::kGrey8);
}

TEST(FakeRenderer, GlErrorRebuildsTheRendererOtherErrorsDoNot) {
  auto control = std::make_shared<test::FakeRendererControl>();
  test::LocalServer s({}, test::fake_renderer_factory(control));
  test::Conn c(s.port(), 30);
  EXPECT_EQ(s.core().renderer_description, "fake renderer (no GL)");
  expect_fake_frame(c.call(render_req(1)));
  EXPECT_EQ(control->created.load(), 1);

  control->fail_other = true;
  test::Reply r = c.call(render_req(2));
  EXPECT_EQ(r.json["error"]["code"], "internal") << r.json;
  expect_fake_frame(c.call(render_req(3)));
  EXPECT_EQ(control->created.load(), 1);  // not a GL error: the renderer is kept
  EXPECT_EQ(s.core().renders->renderer_rebuilds(), 0u);

  s.core().renders->fail_next_render_for_test();
  r = c.call(render_req(4));
  EXPECT_EQ(r.json["error"]["code"], "internal") << r.json;
  EXPECT_NE(r.json["error"]["message"].get<std::string>().find("injected GL error"), std::string::npos);
  expect_fake_frame(c.call(render_req(5)));
  EXPECT_EQ(control->created.load(), 2);
  EXPECT_EQ(s.core().renders->renderer_rebuilds(), 1u);
}

}  // namespace
}  // namespace beamcast
