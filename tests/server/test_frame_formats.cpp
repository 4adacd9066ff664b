// Frame formats negotiated in hello (PROTOCOL.md, "Frame formats"; issue 39):
// raw and raw_zstd frames hold exactly the PNG frame's samples, at 8 and 16
// bits; an unknown or mistyped format is refused with its path and changes
// nothing; hello and stats report the encode pool's size.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "client/client.hpp"
#include "protocol/frame_format.hpp"
#include "render/image.hpp"
#include "tests/server/server_fixture.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

client::RenderResult render_tiny(client::Client& c, int bit_depth) {
  client::RenderRequest req;
  req.scene = test::tiny_scene(24);
  req.output = {{"bit_depth", bit_depth}};
  return c.render(req);
}

TEST(FrameFormats, RawFramesHoldThePngFramesSamples) {
  test::LocalServer s;
  client::Client png;
  png.connect("127.0.0.1", s.port());
  const client::Response hello = png.hello();
  ASSERT_TRUE(hello.ok);
  const json& caps = hello.result()["capabilities"];
  EXPECT_EQ(caps["frame_formats"].get<std::vector<std::string>>(), frame_format_names());
  EXPECT_EQ(hello.result()["frame_format"], "png");  // not asked: PNG, as before
  const int threads = caps["scheduling"]["encode_threads"].get<int>();
  EXPECT_GE(threads, 2);
  EXPECT_EQ(png.stats().result()["encode_threads"], threads);

  for (const std::string format : {"raw", "raw_zstd"}) {
    client::Client raw;
    raw.connect("127.0.0.1", s.port());
    const client::Response h = raw.hello("test", format);
    ASSERT_TRUE(h.ok) << h.error.message;
    EXPECT_EQ(h.result()["frame_format"], format);
    for (int depth : {8, 16}) {
      const client::RenderResult a = render_tiny(png, depth);
      const client::RenderResult b = render_tiny(raw, depth);
      ASSERT_TRUE(a.ok && b.ok);
      ASSERT_EQ(a.frames[0].format, "png");
      ASSERT_EQ(b.frames[0].format, format);
      const Image decoded = decode_png(a.frames[0].png);
      EXPECT_EQ(b.frames[0].bit_depth, depth);
      EXPECT_EQ(b.frames[0].samples, decoded.rgb) << format << " at " << depth << " bits";
    }
  }
}

TEST(FrameFormats, UnknownFormatIsRefusedWithItsPath) {
  test::LocalServer s;
  client::Client c;
  c.connect("127.0.0.1", s.port());
  client::Response r = c.hello("test", "webp");
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.code, "invalid_value");
  EXPECT_EQ(r.error.path, "/params/frame_format");
  EXPECT_NE(r.error.message.find("\"raw_zstd\""), std::string::npos) << r.error.message;
  r = c.call("hello", {{"frame_format", 3}});
  ASSERT_FALSE(r.ok);
  EXPECT_EQ(r.error.code, "wrong_type");
  EXPECT_EQ(r.error.path, "/params/frame_format");
  // Refused hellos changed nothing: frames are still PNG.
  EXPECT_EQ(render_tiny(c, 8).frames.at(0).format, "png");
  // A later hello without frame_format keeps the negotiated one.
  ASSERT_TRUE(c.hello("test", "raw").ok);
  EXPECT_EQ(c.hello().result()["frame_format"], "raw");
  EXPECT_EQ(render_tiny(c, 8).frames.at(0).format, "raw");
}

}  // namespace
}  // namespace beamcast
