// What the request handler needs of a client connection, whatever carries it:
// a BCP1 TCP session (session.hpp) or a WebSocket (http_server.cpp), and the
// core both share: the in-flight limit, the alive flag and the write queue
// with its pause rule. Methods are thread-safe; responses are queued and
// written in order.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"
#include "protocol/frame_format.hpp"
#include "render/accuracy_controller.hpp"
#include "server/video_stream.hpp"

namespace beamcast {

// Per-connection state of `quality: "auto"` renders (the accuracy controller
// of the camera this client is moving). Guarded by `mu`: render completions run
// on worker threads.
struct InteractiveState {
  std::mutex mu;
  std::unique_ptr<AccuracyController> controller;
  std::string scene_key;  // the scene the controller's costs were measured on
  VideoStream video;      // moving frames as video (own lock: VideoStream::mu)
};

// The write side both transports share: responses in order, and the pause
// rule: reading stops once unread responses exceed max_write_queue_bytes and
// resumes when they are down to half of it. Used on the connection's strand.
template <class Item>
class WriteQueue {
 public:
  explicit WriteQueue(std::uint64_t limit) : limit_(limit) {}
  void push(Item item, std::size_t bytes) {
    bytes_ += bytes;
    items_.push_back({std::move(item), bytes});
    if (bytes_ > limit_) paused_ = true;
  }
  bool empty() const { return items_.empty(); }
  Item& front() { return items_.front().item; }
  void pop() {
    bytes_ -= items_.front().bytes;
    items_.pop_front();
  }
  void clear() {
    items_.clear();
    bytes_ = 0;
  }
  // Reading is stopped: the client is not taking its responses.
  bool paused() const { return paused_; }
  // After a write: true if reading was paused and may now resume.
  bool resume() {
    if (!paused_ || bytes_ > limit_ / 2) return false;
    paused_ = false;
    return true;
  }

 private:
  struct Entry {
    Item item;
    std::size_t bytes;
  };
  std::deque<Entry> items_;
  std::uint64_t bytes_ = 0;
  const std::uint64_t limit_;
  bool paused_ = false;
};

class Connection {
 public:
  explicit Connection(int max_inflight) : max_inflight_(max_inflight) {}
  virtual ~Connection() = default;
  // Queues one response; `binary` is its attachment section (may be empty).
  virtual void send(const nlohmann::json& response, std::vector<std::uint8_t> binary = {}) = 0;
  virtual void send_error(const nlohmann::json& id, const ErrorInfo& error) = 0;
  // Per-connection admission of render work (max_inflight_per_connection).
  bool try_begin_render() {
    int current = inflight_.load();
    do {
      if (current >= max_inflight_) return false;
    } while (!inflight_.compare_exchange_weak(current, current + 1));
    return true;
  }
  // Ends one admitted render. Called after its answer has been queued
  // (send or send_error): the sessions post the count's decrement behind
  // that answer on their strand, so the connection is never idle, nor a
  // new request refused as busy, between the two.
  virtual void end_render() { release_render(); }
  // False once the client has gone: its queued renders are dropped.
  std::shared_ptr<const std::atomic<bool>> alive_flag() const { return alive_; }
  // Closes the connection; pending writes are dropped.
  virtual void close() = 0;

  InteractiveState& interactive() { return interactive_; }

  // This connection's identity for the render scheduler's turns (unique in
  // the process, never reused).
  std::uint64_t id() const { return id_; }

  // Whether this connection passed hello's token check (server/auth.hpp);
  // TCP sessions and WebSockets go through the same gate.
  bool authenticated() const { return authenticated_.load(); }
  void set_authenticated() { authenticated_.store(true); }

  // The format of this connection's frames that are not JPEG, as negotiated
  // in hello (params.frame_format); PNG until a hello asks for another.
  FrameFormat frame_format() const { return frame_format_.load(); }
  void set_frame_format(FrameFormat f) { frame_format_.store(f); }

 protected:
  int renders_in_flight() const { return inflight_.load(); }
  void release_render() { inflight_.fetch_sub(1); }
  // The client has gone: its queued renders are dropped.
  void mark_gone() { alive_->store(false); }

 private:
  static std::uint64_t next_id() {
    static std::atomic<std::uint64_t> next{1};
    return next.fetch_add(1);
  }
  const int max_inflight_;
  const std::uint64_t id_ = next_id();
  std::atomic<int> inflight_{0};
  std::shared_ptr<std::atomic<bool>> alive_ = std::make_shared<std::atomic<bool>>(true);
  InteractiveState interactive_;
  std::atomic<bool> authenticated_{false};
  std::atomic<FrameFormat> frame_format_{FrameFormat::kPng};
};

}  // namespace beamcast
