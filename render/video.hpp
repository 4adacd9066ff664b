// Video encoding of the preview's moving frames (issue 42): VP8 or VP9 from
// libvpx, or AV1 from libaom, with low-latency settings (realtime, no lag, no
// alt-ref, constant bitrate, a key frame at the start and on request), and a
// decoder for the tests and the bench. Pure CPU: no GL, no sockets.
//
// Frames are converted from RGB to YUV 4:2:0 with the BT.601 matrix: limited
// range for VP8, full range for VP9 and AV1 (whose streams say so), 10 bits
// for AV1 where it affords them (rgb_to_i420, rgb_to_i010).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "render/image.hpp"

namespace beamcast {

enum class VideoCodec { kVp8, kVp9, kAv1 };

// "vp8", "vp9", "av1": the wire names.
std::string_view video_codec_name(VideoCodec c);
std::optional<VideoCodec> parse_video_codec(std::string_view name);

struct VideoEncoderSettings {
  VideoCodec codec = VideoCodec::kVp8;
  int width = 0, height = 0;
  int bitrate_kbps = 1000;  // the rate control's target
  int threads = 1;          // the encoder's worker threads (VP9, AV1: also tile columns)
  // The encoder's cpu-used: higher is faster and coarser. 0: the codec's
  // default, video_encoder_speed(). The bench tries others
  // (docs/performance.md, "Video preview").
  int speed = 0;
  // > 0: AV1's speed follows the encode time, measured per frame (wall clock,
  // colour conversion included; key frames not counted): one step faster
  // (up to 9) when the mean of the last 3 delta frames is over this many ms,
  // one step back (not below `speed`) when it is under half of it. 0: the
  // speed stays. The server passes half the frame budget of the request
  // (the preview's 33 ms): the encode and the browser's decode together add
  // about one frame's time.
  double max_encode_ms = 0.0;
  // The stream's sample depth: 8, or 10 for AV1 (video_encoder_bit_depth()
  // says when; a 10-bit stream asked for a speed over 6 runs at 6). VP8 and
  // VP9 streams are 8-bit. A 10-bit stream keeps to speeds 5 and 6 and, when
  // even 6 is over max_encode_ms, reopens at 8 bits and speed 7 with a key
  // frame (the frame reports its depth); see video_encoder_bit_depth().
  int bit_depth = 8;
  // AV1 only: the picture is sent as this many horizontal bands, each its
  // own libaom stream of video_band_rows() rows, encoded side by side on
  // threads of their own (`threads` shared among them), each with its share
  // of the bitrate; a client stacks the pictures. video_encoder_bands() says
  // when (frames whose shorter side is 1080 or more, which libaom 3.6
  // otherwise runs at speed 7 and not at all well at 10 bits).
  int bands = 1;
};

// libaom 3.6 runs a realtime AV1 stream whose configured frame has a
// shorter side of 1080 or more at speed 7 or faster, whatever cpu-used says
// (av1_cx_iface.c, set_encoder_config: "1080p performance at speed 5 & 6 is
// quite bad"). Speed 7 is its non-RD mode search, which at 10 bits lost 4-6
// dB (the volume's drag at 1920x1080). A picture of up to this many rows on
// its shorter side gets the speed it asks for.
inline constexpr int kAv1FullSpeedRows = 1079;

// How many horizontal bands a picture is sent as: 1 for VP8 and VP9, and for
// AV1 where the shorter side is at most `max_rows`; else the fewest whose
// bands have at most `max_rows` rows (1920x1080 with the default: 2 bands of
// 540). Each band is then a stream libaom encodes at the speed asked and at
// 10 bits: on the volume's drag at 1920x1080, 2 bands at speed 6 gave 0.6 dB
// more at 8 bits and 1.6-2.7 dB more at 10 bits than the one picture libaom
// ran at 7, for about twice the encode CPU (docs/performance.md, "AV1 in
// bands at 1080 rows"). `max_rows` under the default is for tests (2 bands
// at 512x512).
int video_encoder_bands(VideoCodec codec, int width, int height, int max_rows = kAv1FullSpeedRows);
// The rows of band `index` of `bands` of a picture `height` rows high: each
// but the last ceil(height / bands) rounded up to even (whole 4:2:0 chroma
// rows), the last the rest (0 or less where `height` is too small for
// `bands`: no such layout).
int video_band_rows(int height, int bands, int index);

// The speed (cpu-used) a stream gets by default: VP8 and VP9 8 at any size;
// AV1 5 up to 2^19 pixels (512x512 is 2^18), 6 up to 2^21 (1920x1080), 8
// above (not measured). On the demo drag at 512x512, AV1 at speed 5 was 0.6
// dB better than at 6 at the same bitrate and 6 was 0.8 dB better than 7, for
// 12-18 ms a frame (docs/performance.md, "Video preview: AV1"). One picture
// whose shorter side is 1080 or more runs at 7 whatever this says
// (kAv1FullSpeedRows; the encoder reports 7); in bands it runs at 6.
int video_encoder_speed(VideoCodec codec, int width, int height);

// The sample depth the server gives a stream on `cores` cores: AV1 10 bits
// where it starts at speed 5 (up to 2^19 pixels) and the machine has at
// least 4 cores, else 8; VP8 and VP9 8. Ten bits keep the colour conversion
// and the encoder's predictions finer than a quantizer step at the
// qualities the preview sends: on the volume's drag at 512² AV1 needs a
// fifth fewer bytes at equal PSNR, for 1.1-2 times the encode CPU, which
// the stream gets back from a second thread (video_encoder_threads). On 2
// cores the render competes for both: in the browser test a 10-bit frame at
// speed 6 took 20-35 ms, over the page's 16.5 ms, and the stream fell back.
// libaom 3.6's realtime speeds from 7 on are not usable at 10 bits (7
// crashes, 8 and 9 lose 4-5 dB), hence the fallback to 8 bits
// (VideoEncoderSettings::bit_depth; docs/performance.md, "Ten-bit AV1").
int video_encoder_bit_depth(VideoCodec codec, int width, int height, int cores);

// Whether a 10-bit AV1 stream of width x height is sound with libaom 3.6:
// pictures whose shorter side is under 1080 pixels. At 1080 (1440x1080 and
// 1920x1080, the volume's drag at 1 000 kbit/s) libaom runs at speed 7
// (kAv1FullSpeedRows) and a 10-bit stream was 4.3-4.4 dB worse than an
// 8-bit one at equal bytes; at 1600x900, 1280x720 and 512x512 it was 0.6-0.9
// dB better. The server streams 10 bits only where this holds, whatever
// --preview-bit-depth says: at 1080 rows only in bands.
// With bands the test is on a band (video_band_rows of band 0).
bool video_ten_bit_sound(int width, int height, int bands = 1);

// The encoder's colour conversion: RGB (8-bit, or 16-bit whose high byte is
// kept) to I420 with the BT.601 matrix; U and V are (w+1)/2 x (h+1)/2, each
// from the rounded mean of its 2x2 block (fewer at an odd edge).
// - Limited range (studio swing: Y 16-235, U and V 16-240), the integer form
//   with 8-bit coefficients: VP8, whose stream cannot say otherwise.
// - Full range (Y, U and V 0-255, as JPEG's YCbCr), 16-bit coefficients:
//   AV1, whose sequence header says so (and the matrix, the primaries and the
//   sRGB transfer), and VP9, whose frame headers say range and matrix; the
//   browser converts back with the same matrix.
//   Its steps are finer: on the volume's drag a frame through RGB -> I420 ->
//   RGB alone is 48.6 dB from full accuracy against 47.3 for limited range
//   (the frame itself 49.7; docs/performance.md, "The rate control's start
//   and the colour range").
enum class ColorRange { kLimited, kFull };
struct I420Planes {
  std::uint8_t* y;
  std::uint8_t* u;
  std::uint8_t* v;
  int y_stride, u_stride, v_stride;
};
void rgb_to_i420(const Image& src, const I420Planes& dst, ColorRange range = ColorRange::kLimited);
// The same at 10 bits, full range (Y, U and V 0-1023, U and V centred on
// 512; BT.601, 16-bit coefficients): 10-bit AV1. U and V come from the sum of
// their 2x2 block, not its rounded mean (the finer steps keep what the mean's
// rounding would drop). Strides in samples.
struct I010Planes {
  std::uint16_t* y;
  std::uint16_t* u;
  std::uint16_t* v;
  int y_stride, u_stride, v_stride;
};
void rgb_to_i010(const Image& src, const I010Planes& dst);

// Encoder threads for one stream of width x height on `cores` cores: one per
// started 2^19 pixels (a 512x512 frame: 1; 1280x720: 2; 1920x1080: 4), at
// 10 bits one per started 2^17 (512x512: 2; a 10-bit frame costs 1.1-2
// times the CPU and keeps to speeds 5 and 6), at most 4 and at most
// `cores`. A stream's frames are encoded one at a time, so only threads
// inside the encoder shorten what one frame waits for (docs/performance.md,
// "Video preview", at 1080p, and "Ten-bit AV1").
int video_encoder_threads(int width, int height, int cores, int bit_depth = 8);

struct EncodedVideoFrame {
  std::vector<std::uint8_t> data;  // one compressed frame (the codec's bitstream)
  bool key = false;
  std::int64_t pts = 0;
  int speed = 0;         // the encoder's speed for this frame
  int quantizer = -1;    // the frame's base quantizer, 0-63 (the scale of
                         // rc_max_quantizer)
  int bit_depth = 8;     // the stream's sample depth at this frame
  double encode_ms = 0;  // wall clock, conversion included
  // In bands (VideoEncoderSettings::bands > 1): the bytes of each band's
  // frame, top to bottom; `data` is their concatenation. Empty for one picture.
  std::vector<std::size_t> band_bytes{};
};

class VideoEncoder {
 public:
  // Throws std::runtime_error if libvpx or libaom refuses the settings.
  explicit VideoEncoder(const VideoEncoderSettings& settings);
  ~VideoEncoder();
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // Encodes `img` (the encoder's size; 8- or 16-bit, the high byte is kept)
  // shown at `time_ms` (any monotonic clock; the rate control spends the
  // bitrate over the time between frames). The first frame, and one with
  // `force_key`, is a key frame. Every frame yields one packet (no lag).
  EncodedVideoFrame encode(const Image& img, double time_ms, bool force_key = false);
  void set_bitrate(int kbps);
  // VideoEncoderSettings::max_encode_ms from the next frame on.
  void set_max_encode_ms(double ms) { settings_.max_encode_ms = ms; }

  const VideoEncoderSettings& settings() const { return settings_; }
  std::int64_t frames() const { return frames_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  VideoEncoderSettings settings_;
  std::int64_t frames_ = 0;
  double last_ms_ = 0.0;
  std::int64_t pts_ms_ = 0;
  int base_speed_ = 0;          // settings' speed: adaptation does not go below it
  std::vector<double> recent_;  // encode ms of the last (<= 3) delta frames since the last speed change
  bool key_next_ = false;       // the encoder reopened: its next frame is a key frame
  int slow_windows_ = 0;        // 10 bits at speed 6: windows in a row over max_encode_ms
  std::vector<std::unique_ptr<VideoEncoder>> bands_;  // in bands: one encoder per band
  void adapt_speed(double encode_ms);
  void set_av1_speed_all(int speed);
  void reopen_av1_8bit(int speed);
  EncodedVideoFrame encode_rows(const Image& img, int first_row, double time_ms, bool force_key);
  EncodedVideoFrame encode_bands(const Image& img, bool key, double time_ms);
};

// Decodes a stream frame by frame into 8-bit RGB (tests and the bench).
class VideoDecoder {
 public:
  explicit VideoDecoder(VideoCodec codec);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;
  // The picture of one compressed frame; throws std::runtime_error on a
  // corrupt frame or one that yields no picture.
  Image decode(std::span<const std::uint8_t> frame);
  // A frame in bands: each band's frame to a decoder of its own (made for
  // as many bands as come, anew when that changes, which a stream does only
  // at a key frame), the pictures stacked top to bottom. One part: decode().
  Image decode(std::span<const std::span<const std::uint8_t>> bands);
  // An encoder's frame, in bands or not.
  Image decode(const EncodedVideoFrame& frame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<std::unique_ptr<VideoDecoder>> bands_;
};

// The frame header of the protocol's video frames (PROTOCOL.md, "Video
// preview"): 12 bytes before the codec's frame: "BCV1", a flags byte (bit 0:
// key frame), the codec (0 vp8, 1 vp9, 2 av1), the number of bands (0: one
// picture; 2-16: that many uint32 little-endian byte counts follow the
// header, then the bands' frames top to bottom), a zero byte, and the
// frame's number on its stream (pts, uint32 little-endian; 0 at each key
// frame the stream starts with).
inline constexpr std::size_t kVideoHeaderBytes = 12;
std::vector<std::uint8_t> pack_video_frame(const EncodedVideoFrame& f, VideoCodec codec);
struct VideoFrameView {
  bool key = false;
  VideoCodec codec = VideoCodec::kVp8;
  std::uint32_t pts = 0;
  std::span<const std::uint8_t> data;  // everything after the header (and the band sizes)
  std::vector<std::span<const std::uint8_t>> bands;  // the codec's frames: one, or one per band
};
inline constexpr int kMaxVideoBands = 16;
// Throws std::runtime_error if `bytes` do not start with a valid header.
VideoFrameView unpack_video_frame(std::span<const std::uint8_t> bytes);

}  // namespace beamcast
