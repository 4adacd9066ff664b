#include "server/session.hpp"

#include <boost/asio/post.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include <algorithm>
#include <array>
#include <cstdio>

#include "protocol/request.hpp"
#include "server/request_handler.hpp"
#include "server/memory.hpp"

namespace beamcast {

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

Session::Session(asio::ip::tcp::socket socket, ServerCore& core)
    : Connection(core.config.max_inflight_per_connection),
      socket_(std::move(socket)),
      core_(core),
      read_timer_(socket_.get_executor()),
      write_timer_(socket_.get_executor()),
      writes_(core.config.max_write_queue_bytes) {
  core_.stats.connection_opened();
}

Session::~Session() { core_.stats.connection_closed(); }

void Session::start() {
  asio::post(socket_.get_executor(), [self = shared_from_this()] { self->do_read_header(); });
}

void Session::do_read_header() {
  if (closed_) return;
  state_ = ReadState::kIdle;
  if (writes_.paused()) return;  // resumed by on_write once the client has read enough
  arm_read_deadline();
  // The first byte alone: it starts the message's read_timeout_ms, so a client
  // that sends part of a header and stops is timed out like a slow body.
  read_header_part(0, 1);
}

void Session::read_header_part(std::size_t begin, std::size_t end) {
  read_pending_ = true;
  asio::async_read(socket_, asio::buffer(header_.data() + begin, end - begin),
                   [self = shared_from_this(), end](const boost::system::error_code& ec, std::size_t) {
                     self->read_pending_ = false;
                     if (ec || self->closed_) {
                       self->close_now();  // peer closed or reset: nothing to answer
                     } else if (end == 1) {
                       self->on_first_byte();
                     } else {
                       self->on_header();
                     }
                   });
}

void Session::on_first_byte() {
  state_ = ReadState::kHeader;
  message_clock_.start(core_);
  arm_read_deadline();
  read_header_part(1, header_.size());
}

void Session::on_header() {
  FrameHeader h;
  switch (parse_frame_header(header_, core_.config.max_message_bytes, &h)) {
    case HeaderStatus::kOk:
      break;
    case HeaderStatus::kBadMagic:
    case HeaderStatus::kEmptyJson: {
      // The stream cannot be resynchronized: answer once, then close.
      state_ = ReadState::kStopped;
      read_timer_.cancel();
      if (looks_like_http(header_)) {
        answer_http();
        return;
      }
      // Earlier requests still in flight are answered by nobody: say how many.
      const int dropped = renders_in_flight();
      const ErrorInfo e{"bad_framing",
                        "expected a frame starting with \"BCP1\" and a non-zero JSON length "
                        "(see PROTOCOL.md, Framing); the connection is closed" +
                            (dropped > 0 ? "; " + std::to_string(dropped) +
                                               " earlier request(s) still in flight are cancelled "
                                               "without a response"
                                         : std::string()),
                        ""};
      core_.stats.count_error(e.code);
      enqueue(encode_frame(error_response(nullptr, e).dump()), true);
      return;
    }
    case HeaderStatus::kTooLarge:
      refuse_and_discard({"message_too_large",
                          "message body of " + std::to_string(h.body_length()) +
                              " bytes exceeds max_message_bytes (" +
                              std::to_string(core_.config.max_message_bytes) + ")",
                          ""},
                         h.body_length());
      return;
  }
  // Reserved before the body buffer is allocated, so concurrent large
  // messages are bounded while they arrive as well as while they are parsed.
  ErrorInfo refused;
  if (!core_.request_memory.try_reserve(h.body_length(), &reservation_, &refused)) {
    refuse_and_discard(refused, h.body_length());
    return;
  }
  body_.resize(h.body_length());
  state_ = ReadState::kBody;
  read_pending_ = true;
  asio::async_read(socket_, asio::buffer(body_),
                   [self = shared_from_this(), json_len = h.json_length](
                       const boost::system::error_code& ec, std::size_t n) {
                     self->read_pending_ = false;
                     if (!ec) self->body_.resize(json_len);  // v1 requests carry no attachments
                     self->on_body(ec, n);
                   });
}

void Session::on_body(const boost::system::error_code& ec, std::size_t) {
  if (ec || closed_) {
    close_now();
    return;
  }
  read_timer_.cancel();
  std::size_t bytes = 0;
  {
    const std::string text(body_.begin(), body_.end());
    body_.clear();
    body_.shrink_to_fit();
    bytes = text.size();
    // A scene that reads files is handled on a loader thread; this
    // connection reads on once it has been (message_handled).
    auto resume = [self = shared_from_this(), bytes] {
      asio::post(self->socket_.get_executor(), [self, bytes] { self->message_handled(bytes); });
    };
    if (!handle_message(core_, shared_from_this(), text, Clock::now(), std::move(resume))) return;
  }  // the text is freed before the trim
  message_handled(bytes);
}

void Session::message_handled(std::size_t bytes) {
  reservation_.release();
  release_large_message_memory(bytes);
  do_read_header();
}

void Session::refuse_and_discard(const ErrorInfo& error, std::uint64_t body_bytes) {
  send_error(nullptr, error);
  discard_left_ = body_bytes;
  state_ = ReadState::kDiscard;
  do_discard();
}

void Session::do_discard() {
  if (discard_left_ == 0) {
    do_read_header();
    return;
  }
  body_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(discard_left_, 64 * 1024)));
  read_pending_ = true;
  asio::async_read(socket_, asio::buffer(body_),
                   [self = shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
                     self->read_pending_ = false;
                     if (ec || self->closed_) {
                       self->close_now();
                       return;
                     }
                     self->discard_left_ -= n;
                     self->do_discard();
                   });
}

void Session::arm_read_deadline() {
  if (state_ == ReadState::kIdle) {
    read_timer_.expires_after(std::chrono::milliseconds(core_.config.idle_timeout_ms));
  } else {
    read_timer_.expires_at(message_clock_.deadline(core_));
  }
  read_timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    self->on_read_deadline(ec);
  });
}

void Session::on_read_deadline(const boost::system::error_code& ec) {
  if (ec == asio::error::operation_aborted || closed_) return;
  if (read_timer_.expiry() > Clock::now()) return;  // re-armed since this wait began
  if (state_ == ReadState::kIdle) {
    if (!read_pending_) return;  // paused, not idle
    // Idle is no traffic and no work in flight: a render longer than
    // idle_timeout_ms keeps its connection (PROTOCOL.md, "Limits").
    if (renders_in_flight() > 0 || writing_) {
      arm_read_deadline();
      return;
    }
    std::fprintf(stderr, "beamcast-server: closing idle connection\n");
    close_now();
    return;
  }
  if (state_ == ReadState::kHeader || state_ == ReadState::kBody ||
      state_ == ReadState::kDiscard) {
    if (message_clock_.deadline(core_) > Clock::now()) {
      arm_read_deadline();  // the server was busy meanwhile: that time is not the client's
      return;
    }
    const ErrorInfo e{"timeout",
                      "message incomplete after read_timeout_ms (" +
                          std::to_string(core_.config.read_timeout_ms) + " ms)",
                      ""};
    core_.stats.count_error(e.code);
    state_ = ReadState::kStopped;
    boost::system::error_code ignored;
    socket_.shutdown(asio::ip::tcp::socket::shutdown_receive, ignored);
    enqueue(encode_frame(error_response(nullptr, e).dump()), true);
  }
}

void Session::send(const nlohmann::json& response, std::vector<std::uint8_t> binary) {
  auto frame = encode_frame(response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), binary);
  core_.stats.count_bytes_out(frame.size());
  asio::post(socket_.get_executor(), [self = shared_from_this(), f = std::move(frame)]() mutable {
    self->enqueue(std::move(f), false);
  });
}

void Session::send_error(const nlohmann::json& id, const ErrorInfo& error) {
  core_.stats.count_error(error.code);
  send(error_response(id, error));
}

// A browser or curl on this port: an HTTP request line starts with a method.
bool Session::looks_like_http(std::span<const std::uint8_t> header) {
  static constexpr std::string_view kMethods[] = {"GET ", "HEAD", "POST", "PUT ", "DELE", "OPTI",
                                                  "PATC", "CONN", "TRAC"};
  const std::string_view start(reinterpret_cast<const char*>(header.data()), 4);
  return std::find(std::begin(kMethods), std::end(kMethods), start) != std::end(kMethods);
}

// A short plain HTTP answer in place of a BCP1 error frame: which port this
// is and where the HTTP one is. The rest of the request that has arrived is
// read first, so the close does not reset the connection under the answer.
void Session::answer_http() {
  core_.stats.count_error("wrong_port");
  boost::system::error_code ec;
  std::array<std::uint8_t, 8192> discard;
  for (int i = 0; i < 8 && socket_.available(ec) > 0 && !ec; ++i) {
    socket_.read_some(asio::buffer(discard), ec);
  }
  const int http = core_.config.http_port;
  const std::string body =
      "This is beamcast-server's TCP protocol port (BCP1 frames, protocol/PROTOCOL.md), "
      "not HTTP.\n" +
      (http > 0 ? "The preview page and the HTTP endpoints are on port " + std::to_string(http) +
                      " of this host.\n"
                : std::string("This server has no HTTP port (--http-port -1).\n"));
  const std::string reply = "HTTP/1.1 400 Bad Request\r\nContent-Type: text/plain; charset=utf-8\r\n"
                            "Connection: close\r\nContent-Length: " +
                            std::to_string(body.size()) + "\r\n\r\n" + body;
  enqueue(std::vector<std::uint8_t>(reply.begin(), reply.end()), true);
}

void Session::enqueue(std::vector<std::uint8_t> frame, bool close_after) {
  if (closed_) return;
  const std::size_t bytes = frame.size();
  writes_.push(std::move(frame), bytes);
  if (close_after) close_after_write_ = true;
  if (!writing_) do_write();
}

void Session::do_write() {
  writing_ = true;
  write_timer_.expires_after(std::chrono::milliseconds(core_.config.write_timeout_ms));
  write_timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (ec == asio::error::operation_aborted || self->closed_) return;
    if (self->write_timer_.expiry() > Clock::now()) return;
    std::fprintf(stderr, "beamcast-server: client did not read for write_timeout_ms; closing\n");
    self->core_.stats.count_error("write_timeout");
    // Reset, not a graceful close: what the kernel still holds for a client
    // that stopped reading (megabytes of frames) is dropped at once instead
    // of trickling out through its window after the close (measured: 3.6 MB
    // over 100 s to a client with a 4 KiB receive buffer).
    boost::system::error_code ignored;
    self->socket_.set_option(asio::socket_base::linger(true, 0), ignored);
    self->close_now();
  });
  asio::async_write(socket_, asio::buffer(writes_.front()),
                    [self = shared_from_this()](const boost::system::error_code& ec,
                                                std::size_t n) { self->on_write(ec, n); });
}

void Session::on_write(const boost::system::error_code& ec, std::size_t) {
  write_timer_.cancel();
  if (ec || closed_) {
    close_now();
    return;
  }
  writes_.pop();
  if (!writes_.empty()) {
    do_write();
    return;
  }
  writing_ = false;
  if (close_after_write_) {
    close_now();
    return;
  }
  // An answer is traffic: the idle time starts again once it has gone.
  if (state_ == ReadState::kIdle && read_pending_) arm_read_deadline();
  resume_reading_if_paused();
}

void Session::resume_reading_if_paused() {
  if (writes_.resume() && state_ == ReadState::kIdle && !read_pending_) do_read_header();
}

void Session::end_render() {
  asio::post(socket_.get_executor(), [self = shared_from_this()] { self->release_render(); });
}

void Session::close() {
  asio::post(socket_.get_executor(), [self = shared_from_this()] { self->close_now(); });
}

void Session::close_now() {
  if (closed_) return;
  closed_ = true;
  mark_gone();  // queued renders of this client are dropped
  core_.stats.connection_gone();
  state_ = ReadState::kStopped;
  read_timer_.cancel();
  write_timer_.cancel();
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  writes_.clear();
  reservation_.release();  // a client gone mid-message holds no budget
}

}  // namespace beamcast
