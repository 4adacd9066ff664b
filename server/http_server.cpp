#include "server/http_server.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <vector>

#include "protocol/request.hpp"
#include "server/auth.hpp"
#include "server/connection.hpp"
#include "server/request_handler.hpp"
#include "server/server_core.hpp"

namespace beamcast {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// GET requests carry no body; headers beyond this are refused (431/400).
constexpr std::size_t kMaxHttpHeaderBytes = 16 * 1024;
constexpr std::size_t kMaxHttpBodyBytes = 16 * 1024;
constexpr auto kHttpIdle = std::chrono::seconds(30);

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  asio::io_context& io;
  ServerCore& core;
  tcp::acceptor acceptor;
  std::mutex mu;  // routes and the socket list
  std::map<std::string, Handler, std::less<>> routes;
  std::vector<std::pair<std::string, PrefixHandler>> prefix_routes;
  std::vector<std::weak_ptr<Connection>> sockets;

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

  void do_accept();
};

namespace {

// One WebSocket client: a Connection like a TCP session. Each text message is
// one request; a response is one text message, followed by one binary message
// holding its attachments when it has any.
class WsSession : public Connection, public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, ServerCore& core)
      : ws_(std::move(socket)), core_(core), alive_(std::make_shared<std::atomic<bool>>(true)) {
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
  bool try_begin_render() override {
    int current = inflight_.load();
    do {
      if (current >= core_.config.max_inflight_per_connection) return false;
    } while (!inflight_.compare_exchange_weak(current, current + 1));
    return true;
  }
  void end_render() override { inflight_.fetch_sub(1); }
  std::shared_ptr<const std::atomic<bool>> alive_flag() const override { return alive_; }

  void close() override {
    asio::post(ws_.get_executor(), [self = shared_from_this()] { self->close_now(); });
  }

 private:
  void do_read() {
    if (closed_ || paused_) return;
    read_pending_ = true;
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->on_read(ec);
    });
  }

  void on_read(beast::error_code ec) {
    read_pending_ = false;
    if (ec == websocket::error::message_too_big) {
      // Beast fails the connection with close code 1009 (too big) itself.
      core_.stats.count_error("message_too_large");
      return close_now();
    }
    if (ec || closed_) return close_now();
    if (!ws_.got_text()) {
      send_error(nullptr, ErrorInfo{"bad_request",
                                    "binary WebSocket messages are not requests; send each "
                                    "request as one text message (PROTOCOL.md, WebSocket)",
                                    ""});
    } else {
      const std::string text = beast::buffers_to_string(buffer_.data());
      handle_message(core_, shared_from_this(), text, std::chrono::steady_clock::now());
    }
    buffer_.consume(buffer_.size());
    do_read();
  }

  void enqueue(bool text, std::vector<std::uint8_t> data) {
    if (closed_) return;
    queued_bytes_ += data.size();
    writes_.push_back({text, std::move(data)});
    // Same rule as the TCP session: stop reading requests while the client
    // is not reading its responses.
    if (queued_bytes_ > core_.config.max_write_queue_bytes) paused_ = true;
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
    queued_bytes_ -= writes_.front().second.size();
    writes_.pop_front();
    if (!writes_.empty()) return do_write();
    writing_ = false;
    if (paused_ && queued_bytes_ <= core_.config.max_write_queue_bytes / 2) {
      paused_ = false;
      if (!read_pending_) do_read();
    }
  }

  void close_now() {
    if (closed_) return;
    closed_ = true;
    alive_->store(false);
    writes_.clear();
    queued_bytes_ = 0;
    beast::error_code ignored;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ignored);
    beast::get_lowest_layer(ws_).socket().close(ignored);
  }

  websocket::stream<beast::tcp_stream> ws_;
  ServerCore& core_;
  std::shared_ptr<std::atomic<bool>> alive_;
  std::atomic<int> inflight_{0};
  // Strand-only state.
  beast::flat_buffer buffer_;
  std::deque<std::pair<bool, std::vector<std::uint8_t>>> writes_;
  std::uint64_t queued_bytes_ = 0;
  bool writing_ = false;
  bool paused_ = false;
  bool read_pending_ = false;
  bool closed_ = false;
};

// One HTTP connection: GET requests answered from the routes, keep-alive, and
// the upgrade of /ws to a WebSocket.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, std::shared_ptr<HttpServer::Impl> owner)
      : stream_(std::move(socket)), owner_(std::move(owner)) {}

  void run() {
    asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->do_read(); });
  }

 private:
  void do_read() {
    parser_.emplace();
    parser_->header_limit(kMaxHttpHeaderBytes);
    parser_->body_limit(kMaxHttpBodyBytes);
    stream_.expires_after(kHttpIdle);
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       self->on_read(ec);
                     });
  }

  void on_read(beast::error_code ec) {
    if (ec == http::error::end_of_stream) return shutdown();
    if (ec == http::error::header_limit || ec == http::error::body_limit) {
      return reply_error(http::status::payload_too_large, "request too large\n");
    }
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
      stream_.expires_never();  // the WebSocket has its own timeouts
      auto ws = std::make_shared<WsSession>(stream_.release_socket(), owner_->core);
      {
        std::lock_guard lock(owner_->mu);
        std::erase_if(owner_->sockets, [](const auto& w) { return w.expired(); });
        owner_->sockets.push_back(ws);
      }
      ws->accept(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      return reply_error(http::status::method_not_allowed, "only GET and HEAD\n");
    }
    {
      const std::string_view target(req.target().data(), req.target().size());
      const auto auth = req[http::field::authorization];
      if (!http_request_authorized(owner_->core.config, target.substr(0, target.find('?')),
                                   std::string_view(auth.data(), auth.size()))) {
        return reply_error(http::status::unauthorized,
                           "this server requires a token: Authorization: Bearer <token>\n");
      }
    }
    const HttpReply r = owner_->route(std::string_view(req.target().data(), req.target().size()));
    auto res = std::make_shared<http::response<http::string_body>>(
        static_cast<http::status>(r.status), req.version());
    res->set(http::field::server, "beamcast-server");
    res->set(http::field::content_type, r.content_type);
    res->set(http::field::cache_control, "no-store");
    res->keep_alive(req.keep_alive());
    if (req.method() == http::verb::get) res->body() = r.body;
    res->prepare_payload();
    if (req.method() == http::verb::head) res->content_length(r.body.size());
    write(res);
  }

  void reply_error(http::status status, std::string text) {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::content_type, "text/plain; charset=utf-8");
    res->keep_alive(false);
    res->body() = std::move(text);
    res->prepare_payload();
    write(res);
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
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  }

  beast::tcp_stream stream_;
  std::shared_ptr<HttpServer::Impl> owner_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

void HttpServer::Impl::do_accept() {
  acceptor.async_accept(asio::make_strand(io), [self = shared_from_this()](
                                                   beast::error_code ec, tcp::socket socket) {
    if (ec) {
      if (!self->acceptor.is_open()) return;
      std::fprintf(stderr, "beamcast-server: http accept: %s\n", ec.message().c_str());
    } else {
      std::make_shared<HttpSession>(std::move(socket), self)->run();
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

void HttpServer::add_get_prefix(std::string prefix, PrefixHandler handler) {
  std::lock_guard lock(impl_->mu);
  impl_->prefix_routes.emplace_back(std::move(prefix), std::move(handler));
}

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
