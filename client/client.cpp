#include "client/client.hpp"

#include "protocol/bounded_json.hpp"

#include <algorithm>
#include <functional>
#include <optional>
#include <stdexcept>

#include <boost/asio.hpp>

#include "protocol/frame_format.hpp"
#include "protocol/framing.hpp"

namespace beamcast::client {
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

// Asio's synchronous calls have no deadline, so every operation is started
// asynchronously and the io_context is run until it completes or the deadline
// passes (the pattern of Asio's blocking_tcp_client example).
struct Client::Io {
  asio::io_context ctx;
  tcp::socket socket{ctx};
  std::optional<FrameDecoder> decoder;
  std::vector<std::uint8_t> chunk = std::vector<std::uint8_t>(64 * 1024);

  // Runs until the started operation's handler ran. On timeout `cancel`
  // (default: close the socket) aborts it, its handler is run, and this throws.
  void run_until(Clock::time_point deadline, const std::string& what,
                 const std::function<void()>& cancel = {}) {
    ctx.restart();
    ctx.run_until(deadline);
    if (!ctx.stopped()) {
      boost::system::error_code ignored;
      if (cancel) cancel();
      socket.close(ignored);
      ctx.restart();
      ctx.run();
      throw TransportTimeout(what + ": timed out");
    }
  }
};

const nlohmann::json& Response::result() const {
  static const nlohmann::json kEmpty = nlohmann::json::object();
  auto it = json.find("result");
  return it != json.end() ? *it : kEmpty;
}

Client::Client() : io_(std::make_unique<Io>()) {}
Client::~Client() = default;

bool Client::is_open() const { return io_->socket.is_open(); }

void Client::close() {
  boost::system::error_code ignored;
  io_->socket.shutdown(tcp::socket::shutdown_both, ignored);
  io_->socket.close(ignored);
  io_->decoder.reset();
  kept_.clear();
}

void Client::connect(const std::string& host, std::uint16_t port, Duration timeout) {
  close();
  peer_ = host + ":" + std::to_string(port);
  const std::string what = "connect to " + peer_;
  const auto deadline = Clock::now() + timeout;
  tcp::resolver resolver(io_->ctx);
  boost::system::error_code ec = asio::error::would_block;
  tcp::resolver::results_type endpoints;
  resolver.async_resolve(host, std::to_string(port),
                         [&](const boost::system::error_code& e, tcp::resolver::results_type r) {
                           ec = e;
                           endpoints = std::move(r);
                         });
  io_->run_until(deadline, what, [&] { resolver.cancel(); });
  if (ec) throw std::runtime_error(what + ": cannot resolve host: " + ec.message());
  ec = asio::error::would_block;
  asio::async_connect(io_->socket, endpoints,
                      [&](const boost::system::error_code& e, const tcp::endpoint&) { ec = e; });
  io_->run_until(deadline, what);
  if (ec) {
    close();
    throw std::runtime_error(what + ": " + ec.message());
  }
  // Requests are small and latency is what we measure: do not let Nagle hold them.
  io_->socket.set_option(tcp::no_delay(true));
  io_->decoder.emplace(max_message_bytes_);
}

nlohmann::json Client::send(const nlohmann::json& request) {
  if (!is_open()) throw std::runtime_error("not connected to a beamcast server");
  nlohmann::json req = request;
  if (!req.contains("id")) req["id"] = next_id_++;
  const std::vector<std::uint8_t> frame = encode_frame(req.dump());
  boost::system::error_code ec = asio::error::would_block;
  asio::async_write(io_->socket, asio::buffer(frame),
                    [&](const boost::system::error_code& e, std::size_t) { ec = e; });
  io_->run_until(Clock::now() + receive_timeout_, "send to " + peer_);
  if (ec) {
    close();
    throw std::runtime_error("send to " + peer_ + ": " + ec.message());
  }
  return req["id"];
}

Response Client::read_response() {
  if (!is_open()) throw std::runtime_error("not connected to a beamcast server");
  const auto deadline = Clock::now() + receive_timeout_;
  const std::string what = "receive from " + peer_;
  FrameDecoder::Message msg;
  while (!io_->decoder->next(&msg)) {
    if (io_->decoder->error() != HeaderStatus::kOk) {
      const bool too_large = io_->decoder->error() == HeaderStatus::kTooLarge;
      close();
      throw std::runtime_error(what + (too_large ? ": response larger than the client's limit"
                                                 : ": not a Beamcast (BCP1) frame"));
    }
    boost::system::error_code ec = asio::error::would_block;
    std::size_t n = 0;
    io_->socket.async_read_some(asio::buffer(io_->chunk),
                                [&](const boost::system::error_code& e, std::size_t got) {
                                  ec = e;
                                  n = got;
                                });
    io_->run_until(deadline, what);
    if (ec) {
      close();
      throw std::runtime_error(
          what + (ec == asio::error::eof ? ": server closed the connection" : ": " + ec.message()));
    }
    io_->decoder->feed(std::span<const std::uint8_t>(io_->chunk.data(), n));
  }

  Response r;
  // The same bounded parser as the server's: a hostile server cannot make this
  // client recurse either (responses are shallow; their depth is a few levels).
  BoundedParse parsed = parse_json_bounded(msg.json, JsonLimits{});
  if (parsed.error) {
    close();
    throw std::runtime_error(what + ": response JSON is not acceptable: " + parsed.error->message);
  }
  r.json = std::move(parsed.value);
  if (!r.json.is_object()) {
    close();
    throw std::runtime_error(what + ": response JSON is not an object");
  }
  r.binary = std::move(msg.binary);
  r.id = r.json.value("id", nlohmann::json());
  const auto ok = r.json.find("ok");
  r.ok = ok != r.json.end() && ok->is_boolean() && ok->get<bool>();
  if (!r.ok) {
    const nlohmann::json err = r.json.value("error", nlohmann::json::object());
    auto str = [&](const char* key) {
      const auto it = err.find(key);
      return it != err.end() && it->is_string() ? it->get<std::string>() : std::string();
    };
    r.error = ErrorInfo{str("code"), str("message"), str("path")};
    if (r.error.code.empty()) r.error.code = "bad_response";  // the server sent no code
  }
  return r;
}

Response Client::receive() {
  if (!kept_.empty()) {
    Response r = std::move(kept_.front());
    kept_.pop_front();
    return r;
  }
  return read_response();
}

Response Client::receive_for(const nlohmann::json& id) {
  for (auto it = kept_.begin(); it != kept_.end(); ++it) {
    if (it->id == id || it->id.is_null()) {
      Response r = std::move(*it);
      kept_.erase(it);
      return r;
    }
  }
  for (;;) {
    Response r = read_response();
    if (r.id == id || r.id.is_null()) return r;
    kept_.push_back(std::move(r));
  }
}

Response Client::call(const std::string& method, const nlohmann::json& params) {
  return receive_for(send({{"id", next_id_++}, {"method", method}, {"params", params}}));
}

Response Client::hello(const std::string& client_name, const std::string& frame_format) {
  nlohmann::json params = {{"protocol", 1}, {"client", client_name}};
  if (!frame_format.empty()) params["frame_format"] = frame_format;
  return call("hello", params);
}
Response Client::ping(const nlohmann::json& payload) { return call("ping", payload); }
Response Client::stats() { return call("stats"); }
Response Client::scene_put(const std::string& scene_id, const nlohmann::json& scene) {
  return call("scene.put", {{"scene_id", scene_id}, {"scene", scene}});
}
Response Client::scene_update(const std::string& scene_id, const nlohmann::json& patch) {
  return call("scene.update", {{"scene_id", scene_id}, {"patch", patch}});
}
Response Client::scene_delete(const std::string& scene_id) {
  return call("scene.delete", {{"scene_id", scene_id}});
}

RenderResult Client::render(const RenderRequest& request) {
  nlohmann::json params = nlohmann::json::object();
  if (!request.scene_id.empty()) {
    params["scene_id"] = request.scene_id;
  } else {
    params["scene"] = request.scene;
  }
  if (!request.cameras.is_null()) params["cameras"] = request.cameras;
  if (!request.output.is_null()) params["output"] = request.output;
  params["encoding"] = request.encoding;

  if (request.stream) params["stream"] = true;

  const auto t0 = Clock::now();
  const auto since_t0 = [&] {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  const nlohmann::json id = send({{"id", next_id_++}, {"method", "render"}, {"params", params}});
  RenderResult out;
  out.parts = 0;
  std::vector<char> seen;  // streamed: which camera indices have arrived
  for (;;) {
    Response r = receive_for(id);
    if (out.parts == 0) out.first_part_ms = since_t0();
    ++out.parts;
    out.ok = r.ok;
    if (!r.ok) {  // also ends a stream: frames of earlier parts are dropped with it
      out.error = r.error;
      out.frames.clear();
      out.e2e_ms = since_t0();
      return out;
    }
    const RenderResponse response = read_render_response(r);
    std::vector<RenderedFrame> frames = decode_frames(r, response);
    if (request.stream && !response.stream) {
      throw std::runtime_error("render response: asked to stream, got no \"stream\" part");
    }
    if (request.on_part) request.on_part(response.stream ? response.stream->part : 0, frames);
    const bool last = !response.stream || response.stream->last;
    if (response.stream) {
      // Parts name their frames' camera indices; each index once, all by the last part.
      seen.resize(response.stream->frames, 0);
      for (const RenderedFrame& f : frames) {
        const auto i = static_cast<std::size_t>(f.index);
        if (i >= seen.size() || seen[i]) {
          throw std::runtime_error("render response: streamed frame index " +
                                   std::to_string(f.index) + " out of range or repeated");
        }
        seen[i] = 1;
      }
    }
    for (RenderedFrame& f : frames) out.frames.push_back(std::move(f));
    if (last) {
      if (std::find(seen.begin(), seen.end(), 0) != seen.end()) {
        throw std::runtime_error("render response: the stream ended with frames missing");
      }
      std::sort(out.frames.begin(), out.frames.end(),
                [](const RenderedFrame& a, const RenderedFrame& b) { return a.index < b.index; });
      out.e2e_ms = since_t0();
      out.passes = response.passes;
      out.timings = to_json(response)["timings"];
      out.server_ms = response.timings.server_ms;
      out.network_ms = out.e2e_ms - out.server_ms;
      return out;
    }
  }
}

RenderResponse read_render_response(const Response& response) {
  try {
    return render_response_from_json(response.result(), "/result");
  } catch (const ProtocolError& e) {
    throw std::runtime_error(std::string("malformed render response: ") + e.what());
  }
}

std::vector<RenderedFrame> decode_frames(const Response& response, const RenderResponse& parsed) {
  std::vector<RenderedFrame> frames;
  for (const RenderFrame& f : parsed.frames) {
    RenderedFrame fr;
    fr.camera = f.camera;
    fr.index = static_cast<int>(f.index);
    fr.width = f.width;
    fr.height = f.height;
    fr.bit_depth = f.bit_depth.value_or(8);
    const std::string what = "malformed render response: frame '" + f.camera + "'";
    if (f.attachment) {
      const auto [offset, length] = *f.attachment;
      // Compare without adding, so a huge offset cannot wrap around.
      if (offset > response.binary.size() || length > response.binary.size() - offset) {
        throw std::runtime_error(what + ": attachment [" + std::to_string(offset) + ", +" +
                                 std::to_string(length) + ") outside the " +
                                 std::to_string(response.binary.size()) + "-byte binary section");
      }
      const auto* begin = response.binary.data() + offset;
      fr.png.assign(begin, begin + length);
    } else if (f.data_base64) {
      try {
        fr.png = base64_decode(*f.data_base64);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(what + ": " + e.what());
      }
    } else {
      throw std::runtime_error(what + " has neither attachment nor data_base64");
    }
    fr.format = f.format.value_or("png");
    const std::optional<FrameFormat> raw = parse_frame_format(fr.format);
    if (raw && *raw != FrameFormat::kPng) {
      try {
        fr.samples = decode_raw_frame(fr.png, fr.width, fr.height, fr.bit_depth, *raw);
      } catch (const std::runtime_error& e) {
        throw std::runtime_error(what + ": " + e.what());
      }
    }
    // The timings as sent (gpu_ms, pass_ms, readback_ms, encode_ms).
    fr.timings = nlohmann::json::object();
    const nlohmann::json sent = to_json(f);  // named: items() refers to it
    for (const auto& [key, value] : sent.items()) {
      if (key.ends_with("_ms")) fr.timings[key] = value;
    }
    frames.push_back(std::move(fr));
  }
  return frames;
}

std::vector<RenderedFrame> decode_frames(const Response& response) {
  return decode_frames(response, read_render_response(response));
}

}  // namespace beamcast::client
