// The preview's moving frames as JPEG against a VP8/VP9 stream (issue 42;
// docs/performance.md, "Video preview"). One drag is replayed: the browser
// test's pointer path (tests/preview/browser.mjs, pointerMoves: 2 s, radius
// 100 px on a 512 px canvas) through the page's orbit (a drag across the
// canvas turns half a turn), 30 frames a second, from the scene's camera.
// Every pose is rendered at full accuracy (the reference) and at one
// accuracy level of the preview's ladder (the moving frame); the moving
// frames go through JPEG at several qualities and through the video encoder
// at several bitrates (frames timed at 30 frames/s), are decoded, and each
// displayed frame is compared with the full-accuracy frame of its pose:
// PSNR (RGB, 8 bits) and SSIM (luma, 8x8 windows at a stride of 4, the
// usual constants). Encode is timed per frame in the process's CPU time
// (the encoder's threads included) and in wall-clock time (what a frame
// waits); decode in this thread's CPU time, including the conversion to RGB.
// --threads and --speeds are the encoder's (render/video.hpp; speed 0: the
// codec's default for the size); --codecs the video codecs tried (vp8, vp9,
// av1); --kbps and --jpeg the bitrates and qualities tried;
// --max-encode-ms MS lets AV1's speed follow the encode time as the server's
// does (VideoEncoderSettings::max_encode_ms); --native 1 sends each frame at
// the size the level renders and shows it upscaled bilinearly; --bits 8 or
// 10 sets AV1's sample depth (default 8); --bands N sends AV1 pictures as N
// horizontal bands (0, the default: as the server sends them to the page,
// video_encoder_bands: 2 at 1920x1080, else 1).
//
// Not a test: prints a markdown table, and CSV with --csv FILE (for
// bench/plot_video.py). Usage:
//   beamcast_bench_video [--scene NAME] [--size WxH] [--level L] [--frames N] [--csv FILE]
//                        [--threads N] [--speeds S,S..] [--kbps R,R..] [--jpeg Q,Q..]
//                        [--codecs C,C..] [--max-encode-ms MS] [--native 0|1] [--bits 8|10]
//                        [--bands N]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <utility>
#include <vector>

#include "protocol/data_dir.hpp"
#include "protocol/scene_json.hpp"
#include "render/accuracy_controller.hpp"
#include "render/image.hpp"
#include "render/jpeg.hpp"
#include "render/renderer.hpp"
#include "render/video.hpp"

namespace {

using namespace beamcast;
// CPU time of this thread, ms: the encoders' cost on a shared machine whose
// load makes wall-clock numbers noisy.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

// CPU time of the whole process, ms: the encoder's own threads included.
double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

// Wall-clock ms: what the frame waits for its encode (added latency).
double wall_ms() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// The p-quantile (nearest rank) of v.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::ceil(p * static_cast<double>(v.size()))) - 1;
  return v[std::min(i, v.size() - 1)];
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

Vec3 rotate_about(const Vec3& v, const Vec3& axis, double angle) {
  // Rodrigues' formula, axis of unit length.
  const double c = std::cos(angle), s = std::sin(angle);
  return c * v + s * cross(axis, v) + (dot(axis, v) * (1.0 - c)) * axis;
}

// The drag's poses: the page's orbit about the camera's up axis, driven by the
// browser test's pointer path, sampled at 30 frames/s.
std::vector<Camera> drag_path(const Camera& cam0, int frames) {
  const Vec3 target = cam0.target.value_or(cam0.position + Vec3{0, 0, -5});
  const Vec3 up = normalize(cam0.up);
  const double canvas = 512.0, radius = 100.0, k = 3.14159265358979 / canvas;
  std::vector<Camera> out;
  for (int i = 0; i < frames; ++i) {
    const double t = i / (frames - 1.0);
    const double a = 1.5 * 3.14159265358979 * t;
    const double yaw = -radius * std::sin(a) * k;
    const double pitch = 0.4 * radius * std::sin(2 * a) * k;
    Vec3 d = rotate_about(cam0.position - target, up, yaw);
    const Vec3 side = normalize(cross(up, d));
    d = rotate_about(d, side, -pitch);
    Camera c = cam0;
    c.rotation.reset();
    c.target = target;
    c.position = target + d;
    out.push_back(c);
  }
  return out;
}

// Luma of an 8-bit RGB image (BT.601).
std::vector<double> luma(const Image& img) {
  std::vector<double> y(static_cast<std::size_t>(img.width) * img.height);
  for (std::size_t i = 0; i < y.size(); ++i) {
    y[i] = 0.299 * img.rgb[3 * i] + 0.587 * img.rgb[3 * i + 1] + 0.114 * img.rgb[3 * i + 2];
  }
  return y;
}

double ssim(const Image& a, const Image& b) {
  const std::vector<double> x = luma(a), y = luma(b);
  const int w = a.width, h = a.height, n = 8, stride = 4;
  const double c1 = std::pow(0.01 * 255, 2), c2 = std::pow(0.03 * 255, 2);
  double sum = 0.0;
  int windows = 0;
  for (int wy = 0; wy + n <= h; wy += stride) {
    for (int wx = 0; wx + n <= w; wx += stride) {
      double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const std::size_t p = static_cast<std::size_t>(wy + j) * w + wx + i;
          mx += x[p];
          my += y[p];
          sxx += x[p] * x[p];
          syy += y[p] * y[p];
          sxy += x[p] * y[p];
        }
      }
      const double m = n * n;
      mx /= m;
      my /= m;
      const double vx = sxx / m - mx * mx, vy = syy / m - my * my, cxy = sxy / m - mx * my;
      sum += ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
      ++windows;
    }
  }
  return windows ? sum / windows : 1.0;
}

Image to8(const Image& img) {
  if (img.bit_depth == 8) return img;
  Image o = img;
  o.bit_depth = 8;
  for (auto& s : o.rgb) s = static_cast<std::uint16_t>(s >> 8);
  return o;
}

// Bilinear resampling to w x h with pixel centres aligned (what GL's linear
// blit and a canvas's drawImage do): the display of a frame sent at the
// level's own resolution.
Image upscale_bilinear(const Image& src, int w, int h) {
  if (src.width == w && src.height == h) return src;
  Image o;
  o.width = w;
  o.height = h;
  o.bit_depth = src.bit_depth;
  o.rgb.resize(3 * static_cast<std::size_t>(w) * h);
  const double sx = static_cast<double>(src.width) / w, sy = static_cast<double>(src.height) / h;
  for (int y = 0; y < h; ++y) {
    const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, src.height - 1.0);
    const int y0 = static_cast<int>(fy), y1 = std::min(y0 + 1, src.height - 1);
    const double ty = fy - y0;
    for (int x = 0; x < w; ++x) {
      const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, src.width - 1.0);
      const int x0 = static_cast<int>(fx), x1 = std::min(x0 + 1, src.width - 1);
      const double tx = fx - x0;
      for (int c = 0; c < 3; ++c) {
        auto at = [&](int xx, int yy) {
          return static_cast<double>(src.rgb[3 * (static_cast<std::size_t>(yy) * src.width + xx) + c]);
        };
        const double v = (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) +
                         ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1));
        o.rgb[3 * (static_cast<std::size_t>(y) * w + x) + c] = static_cast<std::uint16_t>(std::lround(v));
      }
    }
  }
  return o;
}

struct Result {
  std::string path;
  double setting = 0;  // JPEG quality or kbit/s
  std::vector<double> psnr{}, ssim{}, encode_ms{}, encode_wall_ms{}, decode_ms{};
  std::size_t bytes = 0, key_bytes = 0;
  int speed = 0;  // the video encoder's at the start (0 for JPEG)
  int bits = 8;   // the video stream's sample depth at the start
  int frames_8bit = 0;  // its frames at 8 bits (a 10-bit stream falls back when too slow)
  int bands = 1;        // horizontal bands a picture is sent as
  std::vector<double> speeds{};  // per frame (with --max-encode-ms it moves)
};

}  // namespace

int main(int argc, char** argv) {
  std::string name = "paper_10sets", csv_path;
  int width = 512, height = 512, level_index = 3, frames = 60, threads = 1;
  int bits = 8;  // AV1's sample depth
  int bands = 0;  // AV1's bands; 0: video_encoder_bands
  bool native = false;  // send the level at the size it renders; the display upscales
  double max_encode_ms = 0.0;  // > 0: AV1's speed follows the encode time (VideoEncoderSettings)
  std::vector<int> speeds{0}, rates{125, 250, 500, 1000, 2000, 4000}, qualities{50, 75, 85, 92};
  std::vector<VideoCodec> codecs{VideoCodec::kVp8, VideoCodec::kVp9, VideoCodec::kAv1};
  auto split = [](const std::string& v) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size();) {
      const std::size_t j = std::min(v.find(',', i), v.size());
      out.push_back(v.substr(i, j - i));
      i = j + 1;
    }
    return out;
  };
  auto int_list = [&](const std::string& v) {
    std::vector<int> out;
    for (const std::string& s : split(v)) out.push_back(std::atoi(s.c_str()));
    return out;
  };
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--scene") name = v;
    else if (a == "--size") std::sscanf(v.c_str(), "%dx%d", &width, &height);
    else if (a == "--level") level_index = std::atoi(v.c_str());
    else if (a == "--frames") frames = std::max(2, std::atoi(v.c_str()));
    else if (a == "--csv") csv_path = v;
    else if (a == "--threads") threads = std::max(1, std::atoi(v.c_str()));
    else if (a == "--speeds") speeds = int_list(v);
    else if (a == "--kbps") rates = int_list(v);
    else if (a == "--jpeg") qualities = int_list(v);
    else if (a == "--native") native = v == "1";
    else if (a == "--bits") bits = std::atoi(v.c_str());
    else if (a == "--bands") bands = std::max(0, std::atoi(v.c_str()));
    else if (a == "--max-encode-ms") max_encode_ms = std::atof(v.c_str());
    else if (a == "--codecs") {
      codecs.clear();
      for (const std::string& s : split(v)) {
        const auto c = parse_video_codec(s);
        if (!c) {
          std::fprintf(stderr, "unknown codec %s\n", s.c_str());
          return 2;
        }
        codecs.push_back(*c);
      }
    }
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  const auto dir = find_data_dir("examples");
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  const Scene scene = load_scene_file(dir / (name + ".json"), opts);
  Camera cam0 = scene.cameras.at(0);
  cam0.width = width;
  cam0.height = height;
  const std::vector<AccuracyLevel> ladder = preview_ladder(scene);
  level_index = std::clamp(level_index, 0, static_cast<int>(ladder.size()) - 1);
  const AccuracyLevel& level = ladder[level_index];
  Scene reduced = scene;
  apply_accuracy_level(level, &reduced);
  FrameOptions fo;
  fo.resolution_scale = level.scale;

  Renderer renderer;
  std::fprintf(stderr, "renderer: %s; %s %dx%d, level %d (%s), %d frames\n",
               renderer.description().c_str(), name.c_str(), width, height, level_index,
               level.label.c_str(), frames);
  std::vector<Image> full, moving;
  const int sw = std::max(1, static_cast<int>(std::lround(width * level.scale)));
  const int sh = std::max(1, static_cast<int>(std::lround(height * level.scale)));
  for (const Camera& c : drag_path(cam0, frames)) {
    full.push_back(to8(renderer.render(scene, {c})[0].image));
    if (native) {
      Camera small = c;
      small.width = sw;
      small.height = sh;
      moving.push_back(to8(renderer.render(reduced, {small})[0].image));
    } else {
      moving.push_back(to8(renderer.render(reduced, {c}, fo)[0].image));
    }
  }
  const int ew = moving[0].width, eh = moving[0].height;
  Result raw{.path = "uncompressed"};
  for (int i = 0; i < frames; ++i) {
    const Image shown = upscale_bilinear(moving[i], width, height);
    raw.psnr.push_back(compare_levels(shown, full[i]).psnr_db);
    raw.ssim.push_back(ssim(shown, full[i]));
  }

  std::vector<Result> results;
  for (int q : qualities) {
    Result r{.path = "jpeg", .setting = static_cast<double>(q)};
    for (int i = 0; i < frames; ++i) {
      double t = thread_cpu_ms();
      const double w0 = wall_ms();
      const auto bytes = encode_jpeg(moving[i], q);
      r.encode_ms.push_back(thread_cpu_ms() - t);
      r.encode_wall_ms.push_back(wall_ms() - w0);
      t = thread_cpu_ms();
      const Image decoded = decode_jpeg(bytes);
      r.decode_ms.push_back(thread_cpu_ms() - t);
      const Image shown = upscale_bilinear(decoded, width, height);
      r.bytes += bytes.size();
      r.psnr.push_back(compare_levels(shown, full[i]).psnr_db);
      r.ssim.push_back(ssim(shown, full[i]));
    }
    results.push_back(std::move(r));
  }
  std::vector<std::pair<VideoCodec, int>> configs;  // codec, speed
  for (VideoCodec codec : codecs) {
    for (int speed : speeds) configs.emplace_back(codec, speed > 0 ? speed : video_encoder_speed(codec, ew, eh));
  }
  for (const auto& [codec, speed] : configs) {
    for (int kbps : rates) {
      Result r{.path = std::string(video_codec_name(codec)), .setting = static_cast<double>(kbps),
               .speed = speed};
      const bool av1 = codec == VideoCodec::kAv1;
      VideoEncoder enc({codec, ew, eh, kbps, threads, speed, max_encode_ms, av1 ? bits : 8,
                        !av1 ? 1 : bands > 0 ? bands : video_encoder_bands(codec, ew, eh)});
      r.bits = enc.settings().bit_depth;
      r.bands = enc.settings().bands;
      r.speed = enc.settings().speed;  // a 10-bit stream keeps to 6
      VideoDecoder dec(codec);
      for (int i = 0; i < frames; ++i) {
        double t = process_cpu_ms();
        const double w0 = wall_ms();
        const EncodedVideoFrame f = enc.encode(moving[i], i * 1000.0 / 30.0);
        r.encode_ms.push_back(process_cpu_ms() - t);
        r.encode_wall_ms.push_back(wall_ms() - w0);
        t = thread_cpu_ms();
        const Image decoded = dec.decode(f);
        r.decode_ms.push_back(thread_cpu_ms() - t);
        const Image shown = upscale_bilinear(decoded, width, height);
        r.bytes += f.data.size();
        if (f.key) r.key_bytes += f.data.size();
        r.speeds.push_back(f.speed);
        if (f.bit_depth == 8) ++r.frames_8bit;
        r.psnr.push_back(compare_levels(shown, full[i]).psnr_db);
        r.ssim.push_back(ssim(shown, full[i]));
      }
      results.push_back(std::move(r));
    }
  }

  const double seconds = frames / 30.0;
  std::printf("\n### %s, %dx%d, moving frames at level %d (%s), %d frames at 30 frames/s\n\n",
              name.c_str(), width, height, level_index, level.label.c_str(), frames);
  std::printf("Without compression the level's frames are %.2f dB PSNR, SSIM %.4f against full accuracy.\n\n",
              mean(raw.psnr), mean(raw.ssim));
  std::printf("Video: %d encoder thread(s). Frames sent at %dx%d%s.\n\n", threads, ew, eh,
              native ? " (the level's own size; shown upscaled bilinearly)" : "");
  if (max_encode_ms > 0) {
    std::printf("AV1's speed follows the encode time against %.1f ms; mean speed over the frames:", max_encode_ms);
    for (const Result& r : results) {
      if (!r.speeds.empty() && r.path == "av1") std::printf(" %g kbit/s %.2f;", r.setting, mean(r.speeds));
    }
    std::printf("\n\n");
  }
  std::printf("| path | bits | speed | setting | KiB/s | Mbit/s | PSNR dB (mean) | PSNR min | SSIM (mean) | encode CPU ms (median) | encode wall ms (median) | encode wall ms (90th pct.) | decode CPU ms (median) | key frame bytes |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  FILE* csv = csv_path.empty() ? nullptr : std::fopen(csv_path.c_str(), "a");
  for (const Result& r : results) {
    const double bps = r.bytes / seconds;
    std::string bits_cell = std::to_string(r.bits);
    if (r.bits == 10 && r.frames_8bit > 0) bits_cell += " (8 from frame " + std::to_string(frames - r.frames_8bit) + ")";
    if (r.path == "jpeg") bits_cell = "8";
    if (r.bands > 1) bits_cell += ", " + std::to_string(r.bands) + " bands";
    std::printf("| %s | %s | %d | %s%g | %.1f | %.3f | %.2f | %.2f | %.4f | %.2f | %.2f | %.2f | %.2f | %zu |\n",
                r.path.c_str(), bits_cell.c_str(), r.speed, r.path == "jpeg" ? "q" : "", r.setting, bps / 1024, bps * 8 / 1e6,
                mean(r.psnr), *std::min_element(r.psnr.begin(), r.psnr.end()), mean(r.ssim),
                median(r.encode_ms), median(r.encode_wall_ms), percentile(r.encode_wall_ms, 0.9),
                median(r.decode_ms), r.key_bytes);
    if (csv) {
      // The last three columns (wall ms, threads, speed) were added after
      // docs/data/video_bench_{512,1080}.csv were recorded, the last two
      // (bits at the start, frames at 8 bits) after
      // docs/data/video_av1_rc_start_full_range/, and the bands after
      // docs/data/video_av1_10bit/.
      std::fprintf(csv, "%s,%dx%d,%s,%g,%.1f,%.3f,%.4f,%.3f,%.3f,%.3f,%.4f,%.3f,%d,%d,%d,%d,%d\n", name.c_str(),
                   width, height, r.path.c_str(), r.setting, bps, mean(r.psnr), mean(r.ssim),
                   median(r.encode_ms), median(r.decode_ms), mean(raw.psnr), mean(raw.ssim),
                   median(r.encode_wall_ms), r.path == "jpeg" ? 1 : threads, r.speed,
                   r.path == "jpeg" ? 8 : r.bits, r.path == "jpeg" ? frames : r.frames_8bit, r.bands);
    }
  }
  if (csv) std::fclose(csv);
  return 0;
}
