#include "server/video_stream.hpp"

#include <chrono>

#include "protocol/check.hpp"
#include "protocol/frame_format.hpp"
#include "server/threads.hpp"

namespace beamcast {

void note_video_request(VideoStream& stream, const VideoParams& params) {
  if (params.keyframe) stream.key_pending = true;
}

VideoFrameReport encode_video_frame(VideoStream& stream, const VideoParams& params,
                                    int default_kbps, const std::string& depth_setting,
                                    int max_band_rows, int width, int height, int bit_depth,
                                    double time_ms, double budget_ms, RenderOutcome* out) {
  BEAMCAST_CHECK(out->pngs.size() == 1 && out->is_jpeg.size() == 1 && !out->is_jpeg[0],
                 "a video frame is one raw frame");
  const auto t0 = std::chrono::steady_clock::now();
  const VideoCodec codec = parse_video_codec(params.codec).value();
  const int kbps = params.bitrate_kbps.value_or(default_kbps);
  Image img;
  img.width = width;
  img.height = height;
  img.bit_depth = bit_depth;
  img.rgb = decode_raw_frame(out->pngs[0], width, height, bit_depth, FrameFormat::kRaw);
  static const int cores = usable_cores();  // the process's cores: read once
  const int bands = params.bands ? video_encoder_bands(codec, width, height, max_band_rows) : 1;
  int bits = 8;
  if (codec == VideoCodec::kAv1 && params.bit_depth == 10 && video_ten_bit_sound(width, height, bands)) {
    bits = depth_setting == "10"  ? 10
           : depth_setting == "8" ? 8
                                  : video_encoder_bit_depth(codec, width, height, cores);
  }
  VideoEncoder* enc = stream.encoder.get();
  if (!enc || enc->settings().codec != codec || enc->settings().width != width ||
      enc->settings().height != height || stream.opened_bit_depth != bits ||
      enc->settings().bands != bands) {
    stream.opened_bit_depth = bits;
    const int threads = video_encoder_threads(width, height, cores, bits);
    stream.encoder = std::make_unique<VideoEncoder>(
        VideoEncoderSettings{codec, width, height, kbps, threads, 0, 0.0, bits, bands});
    enc = stream.encoder.get();
  }
  enc->set_bitrate(kbps);
  // Half the frame's budget: the encode and the browser's decode together
  // stay within about one frame (docs/performance.md, "Video preview: AV1").
  enc->set_max_encode_ms(0.5 * budget_ms);
  const EncodedVideoFrame f = enc->encode(img, time_ms, stream.key_pending);
  stream.key_pending = false;
  out->pngs[0] = pack_video_frame(f, codec);
  VideoFrameReport r;
  r.codec = params.codec;
  r.bitrate_kbps = kbps;
  r.key = f.key;
  r.pts = static_cast<std::uint32_t>(f.pts);
  r.speed = f.speed;
  r.bit_depth = f.bit_depth;
  r.bands = bands;
  r.encode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  out->encode_ms[0] += r.encode_ms;
  out->encode_wall_ms += r.encode_ms;
  return r;
}

void set_video_report(const VideoFrameReport& f, QualityReport* q) {
  q->format = f.codec;
  q->jpeg_quality.reset();
  q->bitrate_kbps = f.bitrate_kbps;
  q->keyframe = f.key;
  q->encoder_speed = f.speed;
  q->encoder_bit_depth = f.bit_depth;
  q->encoder_bands = f.bands;
}

}  // namespace beamcast
