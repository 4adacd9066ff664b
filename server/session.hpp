// One client connection: owns its socket, read buffers and write queue, and
// runs every handler on its own strand (Beast's async-session shape). A
// deadline guards every read and write.
#pragma once

#include <array>
#include <span>
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "protocol/errors.hpp"
#include "protocol/framing.hpp"
#include "server/connection.hpp"
#include "server/server_core.hpp"

namespace beamcast {

class Session : public Connection, public std::enable_shared_from_this<Session> {
 public:
  Session(boost::asio::ip::tcp::socket socket, ServerCore& core);
  ~Session();

  void start();
  // Thread-safe: queues one response frame for writing.
  void send(const nlohmann::json& response, std::vector<std::uint8_t> binary = {}) override;
  void send_error(const nlohmann::json& id, const ErrorInfo& error) override;
  // Thread-safe: closes the connection (pending writes are dropped).
  void close() override;
  // Thread-safe: the decrement runs on this session's strand, after every
  // answer queued before the call (Connection::end_render).
  void end_render() override;


 private:
  // kIdle: between messages (idle_timeout_ms); kHeader, kBody, kDiscard: a
  // message has started (its first byte arrived) and must be complete within
  // read_timeout_ms of that byte.
  enum class ReadState { kIdle, kHeader, kBody, kDiscard, kStopped };

  void do_read_header();
  // Reads header_[begin, end); then on_first_byte (end 1) or on_header.
  void read_header_part(std::size_t begin, std::size_t end);
  void on_first_byte();
  void on_header();
  // An HTTP client on the BCP1 port (curl http://HOST:7878/): a plain HTTP
  // answer that names the HTTP port, then close.
  static bool looks_like_http(std::span<const std::uint8_t> header);
  void answer_http();
  void do_read_body();
  void on_body(const boost::system::error_code& ec, std::size_t n);
  // The message of `bytes` has been handled: its memory is released and the
  // next one read.
  void message_handled(std::size_t bytes);
  // Answers `error` (id null) and reads the message's body away.
  void refuse_and_discard(const ErrorInfo& error, std::uint64_t body_bytes);
  void do_discard();
  // Idle: idle_timeout_ms from now. A started message: read_timeout_ms from
  // its first byte (message_clock_), not re-armed per read.
  void arm_read_deadline();
  void on_read_deadline(const boost::system::error_code& ec);
  void enqueue(std::vector<std::uint8_t> frame, bool close_after);
  void do_write();
  void on_write(const boost::system::error_code& ec, std::size_t n);
  void resume_reading_if_paused();
  void close_now();

  boost::asio::ip::tcp::socket socket_;
  ServerCore& core_;
  boost::asio::steady_timer read_timer_;
  boost::asio::steady_timer write_timer_;

  // Strand-only state.
  ReadState state_ = ReadState::kIdle;
  MessageClock message_clock_;  // read_timeout_ms of the message being read
  bool read_pending_ = false;  // an async read is outstanding
  std::array<std::uint8_t, kFrameHeaderSize> header_{};
  std::vector<std::uint8_t> body_;
  // The message's estimated memory (max_request_memory_bytes), held from its
  // header until it has been handled.
  MemoryBudget::Reservation reservation_;
  std::uint64_t discard_left_ = 0;
  WriteQueue<std::vector<std::uint8_t>> writes_;
  bool writing_ = false;
  bool close_after_write_ = false;
  bool closed_ = false;
};

}  // namespace beamcast
