// An in-process beamcast server on an ephemeral port (GL worker on llvmpipe,
// or the renderer a test passes: fake_renderer.hpp), shared by the
// access-control, overload, soak and renderer tests.
#pragma once

#include <filesystem>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "render/renderer.hpp"
#include "server/server.hpp"
#include "tests/server/test_client.hpp"

namespace beamcast::test {

class LocalServer {
 public:
  explicit LocalServer(ServerConfig c = {}, RendererFactory renderers = gl_renderer_factory({})) {
    c.port = 0;
    if (c.assets_dir.empty()) c.assets_dir = std::filesystem::path(BEAMCAST_SOURCE_DIR) / "examples";
    server_ = std::make_unique<Server>(c, std::move(renderers));
    port_ = server_->start();
    thread_ = std::thread([this] { server_->run(false); });
  }
  ~LocalServer() {
    server_->shutdown();
    thread_.join();
  }
  LocalServer(const LocalServer&) = delete;
  LocalServer& operator=(const LocalServer&) = delete;
  unsigned short port() const { return port_; }
  unsigned short http_port() const { return server_->http_port(); }
  ServerCore& core() { return server_->core(); }

 private:
  std::unique_ptr<Server> server_;
  unsigned short port_ = 0;
  std::thread thread_;
};

inline nlohmann::json tiny_scene(int size = 32) {
  return {{"beams",
           {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"density", "abe"}}}},
          {"cameras",
           {{{"position", {0, 1, 5}}, {"target", {0, 0, 0}}, {"width", size}, {"height", size}}}}};
}

}  // namespace beamcast::test
