#include "server/server.hpp"

#include <cstdlib>
#include <thread>

#include <boost/asio/post.hpp>
#include <boost/asio/strand.hpp>

#include <boost/asio/write.hpp>

#include <algorithm>
#include <cstdio>
#include <csignal>
#include <stdexcept>

#include "protocol/framing.hpp"
#include "protocol/request.hpp"
#include "server/threads.hpp"
#include "server/auth.hpp"
#include "server/http_render.hpp"
#include "server/memory.hpp"
#include "server/session.hpp"

namespace beamcast {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

Server::Server(const ServerConfig& config, RendererFactory renderers)
    : core_(config),
      factory_(std::move(renderers)),
      acceptor_(io_),
      signals_(io_),
      drain_timer_(io_),
      http_(std::make_unique<HttpServer>(io_, core_)) {
  configure_allocator();
  ServerConfig& c = core_.config;
  if (c.encode_threads <= 0) {
    c.encode_threads = default_encode_threads(usable_cores(), c.render_workers, c.network_threads);
  }
  register_preview_routes(*http_, core_);
  register_metrics_routes(*http_, core_);
  register_http_render_routes(*http_, core_);
}

Server::~Server() {
  // Loaders, workers and encoders call into sessions; stop them before the
  // io_context (and the handlers that hold sessions) goes away. Loaders
  // first: they submit renders.
  if (core_.loaders) core_.loaders->stop();
  if (core_.renders) core_.renders->stop();
}

unsigned short Server::start() {
  const ServerConfig& c = core_.config;
  check_bind_policy(c);
  if (c.tls_cert_file.empty() != c.tls_key_file.empty()) {
    throw std::invalid_argument("TLS needs both a certificate and a private key "
                                "(--tls-cert FILE --tls-key FILE), or neither");
  }
  if (!c.tls_cert_file.empty()) {
    if (c.http_port < 0) {
      throw std::invalid_argument(
          "--tls-cert/--tls-key apply to the HTTP listener, which is off (--http-port -1); "
          "the BCP1 TCP port has no TLS (use an SSH tunnel, docs/security.md)");
    }
    http_->enable_tls(c.tls_cert_file, c.tls_key_file);  // before any port is bound
  }
  core_.renders = std::make_unique<RenderService>(factory_, c.render_workers, c.encode_threads,
                                                  c.png, c.max_inflight_total);
  core_.renders->set_batch_window(std::chrono::milliseconds(c.batch_window_ms),
                                  c.scene_limits.max_cameras);
  core_.renders->set_hold_batch_encodes(c.hold_batch_encodes);
  core_.renderer_description = core_.renders->wait_ready();
  // One thread: files are parsed one at a time, as they were on the network
  // thread, so a burst of them peaks no higher.
  core_.loaders = std::make_unique<WorkPool>(1);
  const tcp::endpoint ep(asio::ip::make_address(c.bind), c.port);
  acceptor_.open(ep.protocol());
  acceptor_.set_option(tcp::acceptor::reuse_address(true));
  acceptor_.bind(ep);
  acceptor_.listen(asio::socket_base::max_listen_connections);
  start_heap_trimmer(io_, core_.shutting_down);
  if (c.http_port >= 0) {
    http_port_ = http_->start(c.bind, static_cast<unsigned short>(c.http_port));
  }
  // The bound ports (port 0 picks one): each listener names the other's to a
  // client that came to the wrong one. Set before either accepts.
  core_.config.port = acceptor_.local_endpoint().port();
  if (c.http_port >= 0) core_.config.http_port = http_port_;
  do_accept();
  return acceptor_.local_endpoint().port();
}

void Server::do_accept() {
  acceptor_.async_accept(asio::make_strand(io_), [this](const boost::system::error_code& ec,
                                                        tcp::socket socket) {
    if (ec) {
      if (ec != asio::error::operation_aborted) {
        std::fprintf(stderr, "beamcast-server: accept: %s\n", ec.message().c_str());
      }
      if (!acceptor_.is_open()) return;
      do_accept();
      return;
    }
    if (core_.stats.connections_open() >= core_.config.max_connections) {
      // Over the limit: one error, then close; the other clients carry on.
      const ErrorInfo e{"busy",
                        "max_connections (" + std::to_string(core_.config.max_connections) +
                            ") reached; retry later",
                        ""};
      core_.stats.count_error(e.code);
      auto frame = std::make_shared<std::vector<std::uint8_t>>(
          encode_frame(error_response(nullptr, e).dump()));
      auto sock = std::make_shared<tcp::socket>(std::move(socket));
      asio::async_write(*sock, asio::buffer(*frame),
                        [sock, frame](const boost::system::error_code&, std::size_t) {
                          boost::system::error_code ignored;
                          sock->close(ignored);
                        });
    } else {
      auto session = std::make_shared<Session>(std::move(socket), core_);
      {
        std::lock_guard lock(sessions_mu_);
        std::erase_if(sessions_, [](const auto& w) { return w.expired(); });
        sessions_.push_back(session);
      }
      session->start();
    }
    do_accept();
  });
}

void Server::run(bool handle_signals) {
  if (handle_signals) {
    signals_.add(SIGINT);
    signals_.add(SIGTERM);
    signals_.async_wait([this](const boost::system::error_code& ec, int sig) {
      if (ec) return;
      std::fprintf(stderr, "beamcast-server: signal %d: shutting down\n", sig);
      start_exit_watchdog();
      shutdown();
    });
  }
  // Every network thread, the first too, gets a stack of known size
  // (server/threads.hpp): request handling walks client JSON recursively.
  std::vector<SizedThread> threads;
  for (int i = 0; i < std::max(1, core_.config.network_threads); ++i) {
    threads.emplace_back([this] { io_.run(); });
  }
  for (auto& t : threads) t.join();
}

void Server::start_exit_watchdog() {
  // The last resort (issue 43): whatever a render worker is stuck in, the
  // process ends kExitGraceMs after the drain deadline; the cancel tokens
  // normally end every loop long before.
  constexpr int kExitGraceMs = 2000;
  const auto wait = std::chrono::milliseconds(core_.config.drain_timeout_ms + kExitGraceMs);
  std::thread([wait] {
    std::this_thread::sleep_for(wait);
    std::fprintf(stderr,
                 "beamcast-server: still running %lld ms after the shutdown signal (drain "
                 "deadline + %d ms): exiting now\n",
                 static_cast<long long>(wait.count()), kExitGraceMs);
    std::fflush(stderr);
    std::_Exit(2);
  }).detach();
}

void Server::shutdown() {
  asio::post(io_, [this] {
    if (core_.shutting_down.exchange(true)) return;
    boost::system::error_code ignored;
    acceptor_.close(ignored);
    http_->stop_accepting();
    signals_.cancel(ignored);
    drain_step(std::chrono::steady_clock::now() +
               std::chrono::milliseconds(core_.config.drain_timeout_ms));
  });
}

void Server::drain_step(std::chrono::steady_clock::time_point deadline) {
  const bool busy = core_.renders->inflight() > 0 || core_.loading.load() > 0;
  if (busy && std::chrono::steady_clock::now() < deadline) {
    drain_timer_.expires_after(std::chrono::milliseconds(20));
    drain_timer_.async_wait([this, deadline](const boost::system::error_code& ec) {
      if (!ec) drain_step(deadline);
    });
    return;
  }
  if (core_.renders->inflight() > 0) {
    std::fprintf(stderr,
                 "beamcast-server: drain deadline passed with %d renders in flight: cancelling "
                 "them\n",
                 core_.renders->inflight());
    core_.renders->cancel_all();
  }
  // Let the last responses reach their sockets, then close everything.
  drain_timer_.expires_after(std::chrono::milliseconds(50));
  drain_timer_.async_wait([this](const boost::system::error_code&) {
    std::vector<std::shared_ptr<Session>> open;
    {
      std::lock_guard lock(sessions_mu_);
      for (auto& w : sessions_) {
        if (auto s = w.lock()) open.push_back(std::move(s));
      }
      sessions_.clear();
    }
    for (auto& s : open) s->close();
    http_->close_all();
    if (core_.loaders) core_.loaders->stop();
    core_.renders->stop();
    io_.stop();
  });
}

}  // namespace beamcast
