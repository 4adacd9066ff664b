#include "server/http_server.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <openssl/err.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include "protocol/framing.hpp"
#include "protocol/request.hpp"
#include "server/auth.hpp"
#include "server/connection.hpp"
#include "server/memory.hpp"
#include "server/request_handler.hpp"
#include "server/server_core.hpp"

namespace beamcast {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// After refusing a request whose body was not read, up to this much of it is
// read and dropped before closing, so that the client gets the answer rather
// than a reset (closing a socket with unread data sends RST).
constexpr std::size_t kMaxDrainBytes = 64 * 1024 * 1024;
constexpr auto kHttpIdle = std::chrono::seconds(30);
// A TLS close_notify exchange on a connection we are closing anyway: short.
constexpr auto kTlsShutdown = std::chrono::seconds(5);

// The two byte streams a session runs over: plain TCP, or TLS over TCP
// (--tls-cert/--tls-key). Sessions are templates over these.
using PlainStream = beast::tcp_stream;
using TlsStream = beast::ssl_stream<beast::tcp_stream>;
template <class Stream>
constexpr bool kIsTls = std::is_same_v<Stream, TlsStream>;

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  asio::io_context& io;
  ServerCore& core;
  tcp::acceptor acceptor;
  std::mutex mu;  // routes and the socket list
  std::map<std::string, Handler, std::less<>> routes;
  std::vector<std::pair<std::string, PrefixHandler>> prefix_routes;
  std::map<std::string, PostHandler, std::less<>> post_routes;
  std::vector<std::weak_ptr<Connection>> sockets;
  std::optional<asio::ssl::context> tls;  // set before start(); then read-only

  Impl(asio::io_context& i, ServerCore& c) : io(i), core(c), acceptor(i) {}

  HttpReply route(std::string_view target) {
    const std::string_view path = target.substr(0, target.find('?'));
    Handler exact;
    PrefixHandler prefix;
    std::string_view rest;
    {
      std::lock_guard lock(mu);
      if (auto it = routes.find(path); it != routes.end()) {
        exact = it->second;
      } else {
        for (const auto& [p, h] : prefix_routes) {
          if (path.size() > p.size() && path.starts_with(p)) {
            prefix = h;
            rest = path.substr(p.size());
            break;
          }
        }
      }
    }
    try {
      if (exact) return exact();
      if (prefix) return prefix(rest);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "beamcast-server: http handler %.*s: %s\n",
                   static_cast<int>(path.size()), path.data(), e.what());
      return {500, "text/plain; charset=utf-8", std::string("internal error: ") + e.what() + "\n"};
    }
    return {404, "text/plain; charset=utf-8", "not found\n"};
  }

  PostHandler post_route(std::string_view target) {
    const std::string_view path = target.substr(0, target.find('?'));
    std::lock_guard lock(mu);
    const auto it = post_routes.find(path);
    return it == post_routes.end() ? PostHandler{} : it->second;
  }

  void do_accept();
};

namespace {

// One WebSocket client: a Connection like a TCP session. Each text message is
// one request; a response is one text message, followed by one binary message
// holding its attachments when it has any.
template <class Stream>
class WsSession : public Connection, public std::enable_shared_from_this<WsSession<Stream>> {
  using std::enable_shared_from_this<WsSession<Stream>>::shared_from_this;

 public:
  // Takes over the HTTP session's stream (and its TLS state) after the upgrade.
  WsSession(Stream stream, ServerCore& core)
      : Connection(core.config.max_inflight_per_connection),
        ws_(std::move(stream)),
        core_(core),
        message_timer_(ws_.get_executor()),
        writes_(core.config.max_write_queue_bytes) {
    core_.stats.connection_opened();
  }
  ~WsSession() override { core_.stats.connection_closed(); }

  void accept(http::request<http::string_body> req) {
    websocket::stream_base::timeout t = websocket::stream_base::timeout::suggested(beast::role_type::server);
    t.idle_timeout = std::chrono::milliseconds(core_.config.idle_timeout_ms);
    ws_.set_option(t);
    ws_.read_message_max(core_.config.max_message_bytes);
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close_now();
      self->do_read();
    });
  }

  void send(const nlohmann::json& response, std::vector<std::uint8_t> binary) override {
    // As Session::send: never throw on bytes a client smuggled into a message.
    std::string text = response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    core_.stats.count_bytes_out(text.size() + binary.size());
    asio::post(ws_.get_executor(), [self = shared_from_this(), t = std::move(text),
                                    b = std::move(binary)]() mutable {
      self->enqueue(true, std::vector<std::uint8_t>(t.begin(), t.end()));
      if (!b.empty()) self->enqueue(false, std::move(b));
    });
  }
  void send_error(const nlohmann::json& id, const ErrorInfo& error) override {
    core_.stats.count_error(error.code);
    send(error_response(id, error), {});
  }

  void close() override {
    asio::post(ws_.get_executor(), [self = shared_from_this()] { self->close_now(); });
  }
  void end_render() override {
    asio::post(ws_.get_executor(), [self = shared_from_this()] { self->release_render(); });
  }

 private:
  // A message is read in pieces (read_some) so that its deadline can start
  // with its first bytes: as on TCP, a started message must be complete
  // within read_timeout_ms (PROTOCOL.md, "Limits"). Between messages only
  // Beast's idle timeout (idle_timeout_ms, with pings) applies.
  void do_read() {
    if (closed_ || (writes_.paused() && !in_message_)) return;
    read_pending_ = true;
    ws_.async_read_some(buffer_, 64 * 1024,
                        [self = shared_from_this()](beast::error_code ec, std::size_t) {
                          self->on_read(ec);
                        });
  }

  void arm_message_deadline() {
    message_timer_.expires_at(message_clock_.deadline(core_));
    message_timer_.async_wait([self = shared_from_this()](beast::error_code e) {
      self->on_message_deadline(e);
    });
  }

  void on_message_deadline(beast::error_code ec) {
    if (ec == asio::error::operation_aborted || closed_ || !in_message_) return;
    if (message_timer_.expiry() > std::chrono::steady_clock::now()) return;
    if (message_clock_.deadline(core_) > std::chrono::steady_clock::now()) {
      arm_message_deadline();  // the server was busy meanwhile: not the client's time
      return;
    }
    const ErrorInfo e{"timeout",
                      "message incomplete after read_timeout_ms (" +
                          std::to_string(core_.config.read_timeout_ms) + " ms)",
                      ""};
    send_error(nullptr, e);
    close_after_write_ = true;
  }

  void on_read(beast::error_code ec) {
    read_pending_ = false;
    if (ec == websocket::error::message_too_big) {
      // Beast fails the connection with close code 1009 (too big) itself.
      core_.stats.count_error("message_too_large");
      return close_now();
    }
    if (ec || closed_ || close_after_write_) return close_now();
    if (!in_message_) {
      in_message_ = true;
      message_clock_.start(core_);
      arm_message_deadline();
    }
    if (!ws_.is_message_done()) return do_read();
    in_message_ = false;
    message_timer_.cancel();
    std::size_t bytes = buffer_.size();
    if (!ws_.got_text()) {
      send_error(nullptr, ErrorInfo{"bad_request",
                                    "binary WebSocket messages are not requests; send each "
                                    "request as one text message (PROTOCOL.md, WebSocket)",
                                    ""});
    } else if (MemoryBudget::Reservation reserved;
               reserve_request_memory(core_, *this, bytes, &reserved)) {
      const std::string text = beast::buffers_to_string(buffer_.data());
      buffer_.consume(buffer_.size());
      buffer_.shrink_to_fit();
      // A scene that reads files is handled on a loader thread (as on TCP):
      // the next message is read once it has been.
      auto held = std::make_shared<MemoryBudget::Reservation>(std::move(reserved));
      auto resume = [self = shared_from_this(), held, bytes] {
        asio::post(self->ws_.get_executor(), [self, held, bytes] {
          held->release();
          self->message_handled(bytes);
        });
      };
      if (!handle_message(core_, shared_from_this(), text, std::chrono::steady_clock::now(),
                          std::move(resume))) {
        return;
      }
    }
    message_handled(bytes);
  }

  void message_handled(std::size_t bytes) {
    buffer_.consume(buffer_.size());
    release_large_message_memory(bytes);
    do_read();
  }

  void enqueue(bool text, std::vector<std::uint8_t> data) {
    if (closed_) return;
    const std::size_t bytes = data.size();
    // Pauses reading, as on TCP, while the client is not taking its responses.
    writes_.push({text, std::move(data)}, bytes);
    if (!writing_) do_write();
  }

  void do_write() {
    writing_ = true;
    ws_.text(writes_.front().first);
    ws_.async_write(asio::buffer(writes_.front().second),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      self->on_write(ec);
                    });
  }

  void on_write(beast::error_code ec) {
    if (ec || closed_) return close_now();
    writes_.pop();
    if (!writes_.empty()) return do_write();
    writing_ = false;
    if (close_after_write_) return close_now();
    if (writes_.resume() && !read_pending_) do_read();
  }

  void close_now() {
    if (closed_) return;
    closed_ = true;
    mark_gone();
    core_.stats.connection_gone();
    writes_.clear();
    message_timer_.cancel();
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).socket().close(ignored);
  }

  websocket::stream<Stream> ws_;
  ServerCore& core_;
  asio::steady_timer message_timer_;  // read_timeout_ms of the message being read
  MessageClock message_clock_;
  // Strand-only state.
  beast::flat_buffer buffer_;
  WriteQueue<std::pair<bool, std::vector<std::uint8_t>>> writes_;  // (text?, bytes)
  bool writing_ = false;
  bool read_pending_ = false;
  bool in_message_ = false;         // part of a message has arrived
  bool close_after_write_ = false;  // a timeout was sent: close once written
  bool closed_ = false;
};

// One HTTP connection: GET requests answered from the routes, keep-alive, and
// the upgrade of /ws to a WebSocket.
template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
  using std::enable_shared_from_this<HttpSession<Stream>>::shared_from_this;

 public:
  HttpSession(Stream stream, std::shared_ptr<HttpServer::Impl> owner)
      : stream_(std::move(stream)), owner_(std::move(owner)) {}

  void run() {
    asio::dispatch(stream_.get_executor(), [self = shared_from_this()] {
      if constexpr (kIsTls<Stream>) {
        self->do_handshake();
      } else {
        self->do_read();
      }
    });
  }

 private:
  void do_handshake() {
    // The handshake gets the idle deadline too: a client that connects and
    // says nothing (or speaks plain HTTP) is dropped like an idle one.
    beast::get_lowest_layer(stream_).expires_after(kHttpIdle);
    stream_.async_handshake(asio::ssl::stream_base::server,
                            [self = shared_from_this()](beast::error_code ec) {
                              // Plain HTTP on the TLS port ends here: no page, socket closed.
                              if (ec) return;
                              self->do_read();
                            });
  }

  void do_read() {
    parser_.emplace();
    parser_->header_limit(kMaxHttpHeaderBytes);
    parser_->body_limit(std::max<std::uint64_t>(kMaxHttpBodyBytes,
                                                owner_->core.config.max_message_bytes));
    beast::get_lowest_layer(stream_).expires_after(kHttpIdle);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       self->on_read(ec);
                     });
  }

  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream) return shutdown();
    if (ec == http::error::header_limit) {
      return reply_error(http::status::payload_too_large, "request too large\n");
    }
    if (ec == http::error::body_limit) {
      owner_->core.stats.count_error("message_too_large");
      return reply_error(http::status::payload_too_large,
                         error_body(std::string_view(parser_->get().target().data(),
                                                     parser_->get().target().size()),
                                    "message_too_large",
                                    "the request body is over max_message_bytes (" +
                                        std::to_string(owner_->core.config.max_message_bytes) +
                                        " bytes)"),
                         true);
    }
    if (ec && speaks_bcp1()) return reply_wrong_port();
    if (ec) return;  // timeout, reset, malformed: drop the connection
    http::request<http::string_body> req = parser_->release();
    if (websocket::is_upgrade(req)) {
      if (req.target().substr(0, req.target().find('?')) != "/ws") {
        return reply_error(http::status::not_found, "WebSocket endpoint is /ws\n");
      }
      if (owner_->core.stats.connections_open() >= owner_->core.config.max_connections ||
          owner_->core.shutting_down.load()) {
        // The TCP port's rule: over max_connections, refuse and let the others carry on.
        owner_->core.stats.count_error("busy");
        return reply_error(http::status::service_unavailable,
                           "max_connections reached or shutting down; retry later\n");
      }
      beast::get_lowest_layer(stream_).expires_never();  // the WebSocket has its own timeouts
      auto ws = std::make_shared<WsSession<Stream>>(std::move(stream_), owner_->core);
      {
        std::lock_guard lock(owner_->mu);
        std::erase_if(owner_->sockets, [](const auto& w) { return w.expired(); });
        owner_->sockets.push_back(ws);
      }
      ws->accept(std::move(req));
      return;
    }
    const std::string_view target(req.target().data(), req.target().size());
    const bool post = req.method() == http::verb::post;
    HttpServer::PostHandler post_handler =
        post ? owner_->post_route(target) : HttpServer::PostHandler{};
    if (post && !post_handler) {
      return reply_error(http::status::method_not_allowed,
                         error_body(target, "method_not_allowed",
                                    "POST is for /v1/render; other paths take GET and HEAD"));
    }
    if (!post && req.method() != http::verb::get && req.method() != http::verb::head) {
      return reply_error(http::status::method_not_allowed,
                         error_body(target, "method_not_allowed",
                                    "only GET and HEAD (and POST to /v1/render)"));
    }
    {
      const auto auth = req[http::field::authorization];
      if (!http_request_authorized(owner_->core.config, target.substr(0, target.find('?')),
                                   std::string_view(auth.data(), auth.size()))) {
        owner_->core.stats.count_error("unauthorized");
        return reply_error(http::status::unauthorized,
                           error_body(target, "unauthorized",
                                      "this server requires a token: Authorization: Bearer "
                                      "<token>"));
      }
    }
    if (post) {
      HttpPost p{std::string(target), std::move(req.body()),
                 std::string(req[http::field::authorization]), std::string(req[http::field::accept])};
      const unsigned version = req.version();
      const bool keep_alive = req.keep_alive();
      post_handler(std::move(p), [self = shared_from_this(), version, keep_alive](HttpReply r) {
        asio::post(self->stream_.get_executor(), [self, version, keep_alive, r = std::move(r)] {
          self->write_reply(r, version, keep_alive, false);
        });
      });
      return;
    }
    write_reply(owner_->route(target), req.version(), req.keep_alive(),
                req.method() == http::verb::head);
  }

  void write_reply(const HttpReply& r, unsigned version, bool keep_alive, bool head) {
    auto res = std::make_shared<http::response<http::string_body>>(
        static_cast<http::status>(r.status), version);
    res->set(http::field::server, "beamcast-server");
    res->set(http::field::content_type, r.content_type);
    res->set(http::field::cache_control, "no-store");
    for (const auto& [name, value] : r.headers) res->set(name, value);
    res->keep_alive(keep_alive);
    if (!head) res->body() = r.body;
    res->prepare_payload();
    if (head) res->content_length(r.body.size());
    write(res);
  }

  // The JSON error body of the /v1/ API (PROTOCOL.md, "HTTP render"); plain
  // text on the other paths, as before.
  static HttpReply error_body(std::string_view target, const std::string& code,
                              const std::string& message) {
    if (!target.starts_with("/v1/")) return {0, "text/plain; charset=utf-8", message + "\n"};
    const nlohmann::json j = {{"error", {{"code", code}, {"message", message}, {"path", ""}}}};
    return {0, "application/json", j.dump()};
  }
  void reply_error(http::status status, const HttpReply& body, bool drain = false) {
    reply_error(status, body.body, drain, body.content_type);
  }

  // Closes after the reply; `drain`: the request's body was not read, so read
  // and drop it first (bounded) so that the client sees the reply.
  void reply_error(http::status status, std::string text, bool drain = false,
                   const std::string& content_type = "text/plain; charset=utf-8") {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::content_type, content_type);
    res->keep_alive(false);
    res->body() = std::move(text);
    res->prepare_payload();
    if (!drain || kIsTls<Stream>) return write(res);
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
      if (ec) return;
      beast::error_code ignored;
      beast::get_lowest_layer(self->stream_).socket().shutdown(tcp::socket::shutdown_send, ignored);
      self->drain(0);
    });
  }

  void drain(std::size_t drained) {
    if (drained > kMaxDrainBytes) return;
    if (!scratch_) scratch_ = std::make_shared<std::vector<char>>(64 * 1024);
    beast::get_lowest_layer(stream_).expires_after(kTlsShutdown);
    beast::get_lowest_layer(stream_).async_read_some(
        asio::buffer(*scratch_), [self = shared_from_this(), drained](beast::error_code ec, std::size_t n) {
          if (!ec) self->drain(drained + n);
        });
  }

  // A BCP1 client (`beamcast ping` given this port) sent its frame here: the
  // HTTP parser refused it without consuming it.
  bool speaks_bcp1() const {
    const auto data = buffer_.data();
    return data.size() >= 4 && std::memcmp(data.data(), "BCP1", 4) == 0;
  }

  // Answers that client in its own framing, with an error that names the
  // protocol port, then closes.
  void reply_wrong_port() {
    owner_->core.stats.count_error("wrong_port");
    const ErrorInfo e{"wrong_port",
                      "this is beamcast-server's HTTP port (the preview page, POST /v1/render, "
                      "/metrics, /health); "
                      "the BCP1 protocol is on TCP port " +
                          std::to_string(owner_->core.config.port),
                      ""};
    auto frame = std::make_shared<std::vector<std::uint8_t>>(
        encode_frame(error_response(nullptr, e).dump()));
    asio::async_write(stream_, asio::buffer(*frame),
                      [self = shared_from_this(), frame](beast::error_code, std::size_t) {
                        self->shutdown();
                      });
  }

  void write(std::shared_ptr<http::response<http::string_body>> res) {
    http::async_write(stream_, *res,
                      [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
                        if (ec) return;
                        if (res->need_eof()) return self->shutdown();
                        self->do_read();
                      });
  }

  void shutdown() {
    if constexpr (kIsTls<Stream>) {
      // TLS close_notify, then the socket closes with the session.
      beast::get_lowest_layer(stream_).expires_after(kTlsShutdown);
      stream_.async_shutdown([self = shared_from_this()](beast::error_code) {});
    } else {
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    }
  }

  Stream stream_;
  std::shared_ptr<HttpServer::Impl> owner_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<std::vector<char>> scratch_;  // drain()'s buffer
};

}  // namespace

void HttpServer::Impl::do_accept() {
  acceptor.async_accept(asio::make_strand(io), [self = shared_from_this()](
                                                   beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (!self->acceptor.is_open()) return;
      std::fprintf(stderr, "beamcast-server: http accept: %s\n", ec.message().c_str());
    } else if (self->tls) {
      std::make_shared<HttpSession<TlsStream>>(TlsStream(std::move(socket), *self->tls), self)
          ->run();
    } else {
      std::make_shared<HttpSession<PlainStream>>(PlainStream(std::move(socket)), self)->run();
    }
    self->do_accept();
  });
}

HttpServer::HttpServer(asio::io_context& io, ServerCore& core)
    : impl_(std::make_shared<Impl>(io, core)) {}

HttpServer::~HttpServer() = default;

void HttpServer::add_get(std::string path, Handler handler) {
  std::lock_guard lock(impl_->mu);
  impl_->routes[std::move(path)] = std::move(handler);
}

void HttpServer::add_post(std::string path, PostHandler handler) {
  std::lock_guard lock(impl_->mu);
  impl_->post_routes[std::move(path)] = std::move(handler);
}

void HttpServer::add_get_prefix(std::string prefix, PrefixHandler handler) {
  std::lock_guard lock(impl_->mu);
  impl_->prefix_routes.emplace_back(std::move(prefix), std::move(handler));
}

namespace {

// The first OpenSSL error queued by a failed call, as text ("" when none).
std::string openssl_error() {
  const unsigned long e = ERR_get_error();
  ERR_clear_error();
  if (e == 0) return "";
  char text[256];
  ERR_error_string_n(e, text, sizeof text);
  return text;
}

}  // namespace

void HttpServer::enable_tls(const std::string& cert_file, const std::string& key_file) {
  asio::ssl::context ctx(asio::ssl::context::tls_server);
  // TLS 1.2 and newer only; OpenSSL's defaults pick the ciphers.
  ctx.set_options(asio::ssl::context::default_workarounds | asio::ssl::context::no_sslv2 |
                  asio::ssl::context::no_sslv3 | asio::ssl::context::no_tlsv1 |
                  asio::ssl::context::no_tlsv1_1 | asio::ssl::context::single_dh_use);
  SSL_CTX* native = ctx.native_handle();
  ERR_clear_error();
  if (SSL_CTX_use_certificate_chain_file(native, cert_file.c_str()) != 1) {
    throw std::runtime_error("cannot load TLS certificate (PEM) from '" + cert_file +
                             "': " + openssl_error());
  }
  if (SSL_CTX_use_PrivateKey_file(native, key_file.c_str(), SSL_FILETYPE_PEM) != 1) {
    // OpenSSL checks the key against the loaded certificate here already.
    if (ERR_GET_REASON(ERR_peek_error()) == X509_R_KEY_VALUES_MISMATCH) {
      throw std::runtime_error("TLS private key '" + key_file + "' does not match certificate '" +
                               cert_file + "': " + openssl_error());
    }
    throw std::runtime_error("cannot load TLS private key (PEM) from '" + key_file +
                             "': " + openssl_error());
  }
  if (SSL_CTX_check_private_key(native) != 1) {
    throw std::runtime_error("TLS private key '" + key_file + "' does not match certificate '" +
                             cert_file + "': " + openssl_error());
  }
  impl_->tls.emplace(std::move(ctx));
}

bool HttpServer::tls_enabled() const { return impl_->tls.has_value(); }

unsigned short HttpServer::start(const std::string& bind, unsigned short port) {
  const tcp::endpoint ep(asio::ip::make_address(bind), port);
  impl_->acceptor.open(ep.protocol());
  impl_->acceptor.set_option(tcp::acceptor::reuse_address(true));
  impl_->acceptor.bind(ep);
  impl_->acceptor.listen(asio::socket_base::max_listen_connections);
  impl_->do_accept();
  return impl_->acceptor.local_endpoint().port();
}

void HttpServer::stop_accepting() {
  asio::post(impl_->io, [impl = impl_] {
    beast::error_code ignored;
    impl->acceptor.close(ignored);
  });
}

void HttpServer::close_all() {
  std::vector<std::shared_ptr<Connection>> open;
  {
    std::lock_guard lock(impl_->mu);
    for (auto& w : impl_->sockets) {
      if (auto s = w.lock()) open.push_back(std::move(s));
    }
    impl_->sockets.clear();
  }
  for (auto& s : open) s->close();
}

}  // namespace beamcast
