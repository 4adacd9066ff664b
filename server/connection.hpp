// What the request handler needs of a client connection, whatever carries it:
// a BCP1 TCP session (session.hpp) or a WebSocket (http_server.cpp). Methods
// are thread-safe; responses are queued and written in order.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"
#include "server/accuracy_controller.hpp"

namespace beamcast {

// Per-connection state of `quality: "auto"` renders (the accuracy controller
// of the camera this client is moving). Guarded by `mu`: render completions run
// on worker threads.
struct InteractiveState {
  std::mutex mu;
  std::unique_ptr<AccuracyController> controller;
  std::string scene_key;  // the scene the controller's costs were measured on
};

class Connection {
 public:
  virtual ~Connection() = default;
  // Queues one response; `binary` is its attachment section (may be empty).
  virtual void send(const nlohmann::json& response, std::vector<std::uint8_t> binary = {}) = 0;
  virtual void send_error(const nlohmann::json& id, const ErrorInfo& error) = 0;
  // Per-connection admission of render work.
  virtual bool try_begin_render() = 0;
  virtual void end_render() = 0;
  // False once the client has gone: its queued renders are dropped.
  virtual std::shared_ptr<const std::atomic<bool>> alive_flag() const = 0;
  // Closes the connection; pending writes are dropped.
  virtual void close() = 0;

  InteractiveState& interactive() { return interactive_; }

  // Whether this connection passed hello's token check (server/auth.hpp);
  // TCP sessions and WebSockets go through the same gate.
  bool authenticated() const { return authenticated_.load(); }
  void set_authenticated() { authenticated_.store(true); }

 private:
  InteractiveState interactive_;
  std::atomic<bool> authenticated_{false};
};

}  // namespace beamcast
