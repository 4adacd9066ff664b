// A connection's video stream (issue 42; PROTOCOL.md, "Video preview"): the
// moving frames of `quality: "auto"` renders that ask for "video" are encoded
// by one VP8/VP9/AV1 encoder kept across the connection's requests, so each
// frame is predicted from the previous one. Still frames stay PNG.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "protocol/render_response.hpp"
#include "protocol/request.hpp"
#include "render/video.hpp"
#include "server/render_service.hpp"

namespace beamcast {

struct VideoStream {
  // Held from a frame's encode to its send, so frames leave in the order the
  // encoder made them (the order a decoder needs).
  std::mutex mu;
  std::unique_ptr<VideoEncoder> encoder;
  int opened_bit_depth = 8;  // the depth the encoder was made with (it may fall back to 8)
  bool key_pending = false;  // a key frame was asked for and not yet sent
};

struct VideoFrameReport {
  std::string codec;
  int bitrate_kbps = 0;
  bool key = false;
  std::uint32_t pts = 0;
  int speed = 0;  // the encoder's speed (cpu-used) for this frame
  int bit_depth = 8;  // the stream's sample depth at this frame
  int bands = 1;      // horizontal bands the picture went as
  double encode_ms = 0.0;
};

// Notes a key-frame request of `params` (which may come with a still frame:
// the next moving frame is then the key frame).
void note_video_request(VideoStream& stream, const VideoParams& params);

// Encodes the one frame of `out`, raw samples (FrameFormat::kRaw) at
// `bit_depth`, into `stream` and replaces its bytes with the packed video
// frame (render/video.hpp: the BCV1 header and the codec's frame). A new
// encoder, and so a key frame, for the first frame, a new codec and a new
// frame size or a new depth; the bitrate is params' or `default_kbps`. The
// stream's depth: 10 bits for AV1 where the client decodes them
// (params.bit_depth) and `depth_setting` (the server's --preview-bit-depth:
// "auto", "8", "10") allows, else 8. An AV1 picture whose shorter side is
// over `max_band_rows` goes as bands (video_encoder_bands) to a client that
// stacks them (params.bands), else as one picture. The encode time is
// added to the outcome's encode times (the accuracy controller's frame cost).
// An AV1 stream's speed follows its encode time against half of `budget_ms`,
// the frame budget of the request (VideoEncoderSettings::max_encode_ms).
// Call with stream.mu held. Throws std::runtime_error if the encoder fails.
VideoFrameReport encode_video_frame(VideoStream& stream, const VideoParams& params,
                                    int default_kbps, const std::string& depth_setting,
                                    int max_band_rows, int width, int height, int bit_depth,
                                    double time_ms, double budget_ms, RenderOutcome* out);

// The "quality" block of a video frame: the codec as its format, the
// stream's bitrate and the key-frame flag in place of a JPEG quality.
void set_video_report(const VideoFrameReport& f, QualityReport* q);

}  // namespace beamcast
