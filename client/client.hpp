// Synchronous client of the Beamcast wire protocol (protocol/PROTOCOL.md).
//
// One Client owns one TCP connection. Calls block; every network wait has a
// deadline. Errors the server reports (ok: false) come back as values; a broken
// transport (refused, closed, timed out, not speaking BCP1) throws
// std::runtime_error. Requests may be pipelined with send(); responses that
// arrive for other ids while call()/receive_for() waits are kept for later.
//
// Depends on protocol/ (framing, ErrorInfo, RenderResponse) only: no GL, no render/.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/base64.hpp"
#include "protocol/errors.hpp"
#include "protocol/render_response.hpp"

namespace beamcast::client {

// --- small codecs, no I/O (unit-tested in tests/unit/test_client_codec.cpp) ---

struct Endpoint {
  std::string host;
  std::uint16_t port = 0;
};

// Parses "HOST:PORT" ("[v6addr]:PORT" for IPv6). Throws std::invalid_argument
// naming the text and what is wrong with it.
Endpoint parse_endpoint(std::string_view text);

// base64_encode / base64_decode: protocol/base64.hpp.

// --- responses ---

struct Response {
  nlohmann::json id;                 // as sent back: integer, string or null
  nlohmann::json json;               // the whole response object
  std::vector<std::uint8_t> binary;  // the attachments section
  bool ok = false;
  ErrorInfo error;  // set when !ok
  // The "result" object (empty object when absent).
  const nlohmann::json& result() const;
};

struct RenderedFrame;

struct RenderRequest {
  nlohmann::json scene;             // inline scene object; or
  std::string scene_id;             // a stored scene (exactly one of the two)
  nlohmann::json cameras;           // optional camera overrides (array), null for none
  nlohmann::json output;            // optional output overrides (object), null for none
  std::string encoding = "binary";  // "binary" (attachments) or "base64"
  // Streaming (PROTOCOL.md, "Streaming"; the server lists "stream" in hello's
  // capabilities): the server sends each GPU batch's frames as they finish.
  // render() still returns every frame, in camera order; `on_part`, if set,
  // sees each part's frames as it arrives (part number, frames).
  bool stream = false;
  std::function<void(int part, const std::vector<RenderedFrame>& frames)> on_part;
};

struct RenderedFrame {
  std::string camera;  // camera name, else "camera_<index>" (as the server names it)
  int index = 0;
  int width = 0;
  int height = 0;
  int bit_depth = 8;
  std::string format = "png";    // "png", "jpeg", or what hello negotiated: "raw", "raw_zstd"
  std::vector<std::uint8_t> png;  // the frame's bytes as sent, in `format`
  // "raw" and "raw_zstd" frames: the samples, unpacked and checked against the
  // frame's size (R, G, B per pixel, rows from the top; protocol/frame_format.hpp).
  std::vector<std::uint16_t> samples;
  nlohmann::json timings;  // gpu_ms, pass_ms, readback_ms, encode_ms as sent
};

struct RenderResult {
  bool ok = false;
  ErrorInfo error;  // set when !ok
  std::vector<RenderedFrame> frames;
  nlohmann::json passes;   // pass names that ran
  nlohmann::json timings;  // queue_ms, render_ms, readback_ms, encode_ms, server_ms
  double e2e_ms = 0;       // client wall time: request written -> response read
  double server_ms = 0;    // timings.server_ms
  double network_ms = 0;   // e2e_ms - server_ms: wire, kernel and client decode time
  int parts = 1;           // response messages (streamed: one per part)
  double first_part_ms = 0;  // client wall time until the first message (all of it unstreamed)
};

// --- the client ---

// A network wait that ran past its deadline (connect or receive): thrown by
// Client as this subclass of std::runtime_error, so callers that retry can
// tell "no answer" (retrying waits as long again) from a refused or dropped
// connection.
class TransportTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Client {
 public:
  using Duration = std::chrono::milliseconds;

  Client();
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Resolves and connects within `timeout`; throws std::runtime_error.
  void connect(const std::string& host, std::uint16_t port, Duration timeout = Duration{5000});
  void close();
  bool is_open() const;

  // Deadline of each receive (a render of a large scene may take a while).
  void set_receive_timeout(Duration timeout) { receive_timeout_ = timeout; }
  // Largest response body accepted; past it the stream is treated as broken.
  void set_max_message_bytes(std::uint64_t bytes) { max_message_bytes_ = bytes; }

  // Writes one request frame. A request without "id" gets the next
  // auto-incremented integer id. Returns the id used.
  nlohmann::json send(const nlohmann::json& request);
  // The next response: a kept one first (oldest first), else from the socket.
  Response receive();
  // The response to `id`; others arriving meanwhile are kept. A response with
  // a null id (the server could not read the request's id: bad framing,
  // oversized message, connection refused as busy) is also returned here,
  // since it cannot be matched and would otherwise be waited past forever.
  Response receive_for(const nlohmann::json& id);
  // send + receive_for with a fresh id.
  Response call(const std::string& method, const nlohmann::json& params = nlohmann::json::object());

  // `frame_format` (PROTOCOL.md, "Frame formats"): "raw" or "raw_zstd" asks
  // for this connection's frames as samples; empty: not asked (PNG).
  Response hello(const std::string& client_name = "beamcast-cpp/0.1.0",
                 const std::string& frame_format = "");
  Response ping(const nlohmann::json& payload = nlohmann::json::object());
  Response stats();
  Response scene_put(const std::string& scene_id, const nlohmann::json& scene);
  Response scene_update(const std::string& scene_id, const nlohmann::json& patch);
  Response scene_delete(const std::string& scene_id);

  // Renders and decodes the frames (from attachments or base64). A response
  // that contradicts the protocol (attachment outside the binary section,
  // bad base64) throws std::runtime_error.
  RenderResult render(const RenderRequest& request);

  std::string peer() const { return peer_; }

 private:
  struct Io;  // Boost.Asio state, kept out of this header
  Response read_response();

  std::unique_ptr<Io> io_;
  std::string peer_;
  std::int64_t next_id_ = 1;
  Duration receive_timeout_{60000};
  std::uint64_t max_message_bytes_ = std::uint64_t{1} << 31;
  std::deque<Response> kept_;  // received but not yet asked for, in arrival order
};

// The result of a successful render response, typed; a result that breaks the
// protocol throws std::runtime_error naming the bad field's pointer.
RenderResponse read_render_response(const Response& response);
// Decodes the frames of a successful render response (exposed for tests).
std::vector<RenderedFrame> decode_frames(const Response& response);
std::vector<RenderedFrame> decode_frames(const Response& response, const RenderResponse& parsed);

}  // namespace beamcast::client
