// The HTTP listener of beamcast-server: GET routes registered by name (the
// preview page, its scene lists, and whatever else a component adds, e.g.
// /metrics), POST routes answered asynchronously (/v1/render), and WebSocket connections on /ws that speak the same JSON
// requests as the BCP1 TCP protocol (protocol/PROTOCOL.md, "WebSocket").
// Optionally TLS (HTTPS/WSS) with enable_tls(); the BCP1 port stays plain.
//
// Routes are registered before start(); handlers run on a network thread and
// must be thread-safe. Binds loopback by default, like the TCP port.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <boost/asio/io_context.hpp>

namespace beamcast {

struct ServerCore;

// Headers beyond this are refused (413). A body may hold up to
// max_message_bytes (POST /v1/render carries a scene), at least this much.
// Fixed; reported by hello's limits (server/settings.cpp).
inline constexpr std::size_t kMaxHttpHeaderBytes = 16 * 1024;
inline constexpr std::size_t kMaxHttpBodyBytes = 16 * 1024;

struct HttpReply {
  HttpReply() = default;
  HttpReply(int s, std::string type, std::string text,
            std::vector<std::pair<std::string, std::string>> extra = {})
      : status(s), content_type(std::move(type)), body(std::move(text)), headers(std::move(extra)) {}
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  // extra response headers
};

// What a POST handler sees of its request.
struct HttpPost {
  std::string target;  // path and query string
  std::string body;    // at most max_message_bytes
  std::string authorization;
  std::string accept;
};

class HttpServer {
 public:
  using Handler = std::function<HttpReply()>;
  // Gets the rest of the path after the prefix (already checked to be non-empty).
  using PrefixHandler = std::function<HttpReply(std::string_view rest)>;
  // Answers by calling `reply` once, from any thread; the connection reads
  // its next request only after that reply has been written.
  using PostHandler = std::function<void(HttpPost request, std::function<void(HttpReply)> reply)>;

  HttpServer(boost::asio::io_context& io, ServerCore& core);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Exact path (the query string is ignored when matching). A later
  // registration of the same path replaces the earlier one.
  void add_get(std::string path, Handler handler);
  // Every path that starts with `prefix` (e.g. "/api/examples/") and has more after it.
  void add_get_prefix(std::string prefix, PrefixHandler handler);
  // Exact path for POST (the query string is ignored when matching). A POST
  // body may hold up to max_message_bytes; GET routes answer only POST's 405.
  void add_post(std::string path, PostHandler handler);

  // Serves HTTPS and WSS instead of HTTP and WS (call before start()). Loads
  // a PEM certificate chain and its PEM private key; throws std::runtime_error
  // naming the file and OpenSSL's reason when either cannot be loaded or the
  // key does not match the certificate.
  void enable_tls(const std::string& cert_file, const std::string& key_file);
  bool tls_enabled() const;

  // Binds and starts accepting; returns the bound port (useful with port 0).
  unsigned short start(const std::string& bind, unsigned short port);
  // Stops accepting new connections (shutdown, first step).
  void stop_accepting();
  // Closes every open WebSocket (shutdown, last step).
  void close_all();

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

// The preview page (server/preview/) and the small JSON API it uses:
// GET /, /preview.js, /preview.css, /api/scenes, /api/scenes/<id>,
// /api/examples/<name>.json.
void register_preview_routes(HttpServer& http, ServerCore& core);

}  // namespace beamcast
