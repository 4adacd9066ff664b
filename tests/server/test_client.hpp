// A deliberately plain blocking connection for server tests: it can send raw
// bytes (malformed frames included) and read whole frames with a timeout.
#pragma once

#include <sys/socket.h>
#include <sys/time.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "protocol/framing.hpp"
#include "protocol/render_response.hpp"

namespace beamcast::test {

struct Reply {
  nlohmann::json json;
  std::vector<std::uint8_t> binary;
};

// The typed result of a successful render reply (throws ProtocolError naming
// the bad field if the server broke the format).
inline RenderResponse render_result(const Reply& r) {
  return render_response_from_json(r.json.at("result"), "/result");
}

// The encoded image of frame `i` of a render reply with attachments.
inline std::vector<std::uint8_t> frame_bytes(const Reply& r, std::size_t i = 0) {
  const RenderResponse res = render_result(r);
  const std::optional<Attachment> att = res.frames.at(i).attachment;
  if (!att || att->offset > r.binary.size() || att->length > r.binary.size() - att->offset) {
    throw std::runtime_error("frame " + std::to_string(i) +
                             " has no attachment in the binary part");
  }
  const auto begin = r.binary.begin() + static_cast<std::ptrdiff_t>(att->offset);
  return {begin, begin + static_cast<std::ptrdiff_t>(att->length)};
}

class Conn {
 public:
  explicit Conn(unsigned short port, int timeout_s = 60) : socket_(io_) {
    socket_.connect({boost::asio::ip::make_address("127.0.0.1"), port});
    timeval tv{timeout_s, 0};
    setsockopt(socket_.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  void send_raw(const std::vector<std::uint8_t>& bytes) {
    boost::asio::write(socket_, boost::asio::buffer(bytes));
  }
  void send_raw(const std::string& bytes) {
    boost::asio::write(socket_, boost::asio::buffer(bytes));
  }
  void send_text(const std::string& json_text) { send_raw(encode_frame(json_text)); }
  void send(const nlohmann::json& j) { send_text(j.dump()); }
  // Reads one frame; throws boost::system::system_error on EOF or timeout.
  Reply recv() {
    std::array<std::uint8_t, kFrameHeaderSize> h{};
    boost::asio::read(socket_, boost::asio::buffer(h));
    FrameHeader fh;
    if (parse_frame_header(h, 1ull << 32, &fh) != HeaderStatus::kOk) {
      throw std::runtime_error("server sent a bad frame header");
    }
    std::vector<std::uint8_t> body(fh.body_length());
    boost::asio::read(socket_, boost::asio::buffer(body));
    Reply r;
    r.json = nlohmann::json::parse(body.begin(), body.begin() + fh.json_length);
    r.binary.assign(body.begin() + fh.json_length, body.end());
    return r;
  }
  Reply call(const nlohmann::json& j) {
    send(j);
    return recv();
  }
  // True if the server has closed the connection (reads EOF).
  bool closed_by_peer() {
    std::uint8_t b;
    boost::system::error_code ec;
    socket_.read_some(boost::asio::buffer(&b, 1), ec);
    return ec == boost::asio::error::eof || ec == boost::asio::error::connection_reset;
  }
  void close() { socket_.close(); }
  int native_handle() { return socket_.native_handle(); }

 private:
  boost::asio::io_context io_;
  boost::asio::ip::tcp::socket socket_;
};

}  // namespace beamcast::test
