// A real server (llvmpipe) on ephemeral ports for the HTTP listener's tests,
// and blocking HTTP/1.1 requests to it (test_http_preview.cpp,
// test_http_render.cpp).
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "server/server.hpp"

namespace beamcast::test {

class HttpTestServer {
 public:
  explicit HttpTestServer(ServerConfig c = {}) {
    c.port = 0;
    c.http_port = 0;
    c.assets_dir = std::filesystem::path(BEAMCAST_SOURCE_DIR) / "examples";
    server_ = std::make_unique<Server>(c, gl_renderer_factory({}));
    server_->http().add_get("/extra", [] { return HttpReply{200, "text/plain", "extra route\n"}; });
    port_ = server_->start();
    thread_ = std::thread([this] { server_->run(false); });
  }
  ~HttpTestServer() {
    server_->shutdown();
    thread_.join();
  }
  HttpTestServer(const HttpTestServer&) = delete;
  HttpTestServer& operator=(const HttpTestServer&) = delete;
  unsigned short http_port() const { return server_->http_port(); }
  unsigned short port() const { return port_; }  // the BCP1 TCP port
  ServerCore& core() { return server_->core(); }

 private:
  std::unique_ptr<Server> server_;
  std::thread thread_;
  unsigned short port_ = 0;
};

// One request on a fresh connection; `headers` are added as given.
inline boost::beast::http::response<boost::beast::http::string_body> http_request(
    unsigned short port, boost::beast::http::verb verb, const std::string& target,
    std::string body = {}, const std::vector<std::pair<std::string, std::string>>& headers = {}) {
  namespace asio = boost::asio;
  namespace beast = boost::beast;
  namespace http = beast::http;
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  stream.expires_after(std::chrono::seconds(120));
  http::request<http::string_body> req{verb, target, 11};
  req.set(http::field::host, "127.0.0.1");
  for (const auto& [name, value] : headers) req.set(name, value);
  if (verb != http::verb::get && verb != http::verb::head) {
    req.body() = std::move(body);
    req.prepare_payload();
  }
  http::write(stream, req);
  beast::flat_buffer buf;
  http::response_parser<http::string_body> parser;
  parser.body_limit(1u << 30);
  parser.skip(verb == http::verb::head);  // a HEAD response has a length but no body
  http::read(stream, buf, parser);
  return parser.release();
}

inline boost::beast::http::response<boost::beast::http::string_body> get(
    unsigned short port, const std::string& target,
    boost::beast::http::verb verb = boost::beast::http::verb::get) {
  return http_request(port, verb, target);
}

}  // namespace beamcast::test
