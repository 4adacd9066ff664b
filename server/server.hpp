// The TCP server: accepts connections (one Session each), owns the render
// service and the scene store, and shuts down gracefully.
#pragma once

#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "server/http_server.hpp"
#include "server/render_service.hpp"
#include "server/server_core.hpp"

namespace beamcast {

class Session;

class Server {
 public:
  Server(const ServerConfig& config, RendererFactory renderers);
  ~Server();

  // Starts the render workers (waiting for their GL contexts), binds and
  // starts accepting. Returns the bound port. Throws on failure.
  unsigned short start();
  // Runs the network threads until shutdown completes. With `handle_signals`,
  // SIGINT and SIGTERM start a graceful shutdown.
  void run(bool handle_signals);
  // Thread-safe: stop accepting, refuse new work, let in-flight renders finish
  // (up to drain_timeout_ms), then close every connection and stop.
  void shutdown();

  ServerCore& core() { return core_; }
  // The HTTP listener: register GET routes before start().
  HttpServer& http() { return *http_; }
  // Its bound port once started (0 when config.http_port is -1).
  unsigned short http_port() const { return http_port_; }

 private:
  void do_accept();
  void drain_step(std::chrono::steady_clock::time_point deadline);
  // After a shutdown signal (run with handle_signals only): a detached
  // thread that ends the process drain_timeout_ms + 2 s later, stuck
  // worker or not.
  void start_exit_watchdog();

  ServerCore core_;
  RendererFactory factory_;
  boost::asio::io_context io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::signal_set signals_;
  boost::asio::steady_timer drain_timer_;
  std::unique_ptr<HttpServer> http_;
  unsigned short http_port_ = 0;
  std::mutex sessions_mu_;
  std::vector<std::weak_ptr<Session>> sessions_;
};

}  // namespace beamcast
