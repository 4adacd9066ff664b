// Frame encoders, cost against size (docs/performance.md, "Frame encoders"):
// every PNG in the given directories (the examples' frames, rendered with
// `beamcast render`) is encoded by each candidate the server can use, checked
// to decode to the same samples, and timed (thread CPU time, least of repeats). Prints two markdown tables (MB/s
// of raw RGB input per core, and bytes), one row per frame, and the totals.
//   beamcast_bench_png [--min-ms 300] DIR...
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "protocol/frame_format.hpp"
#include "render/image.hpp"

namespace {

using namespace beamcast;
// CPU time of this thread: what an encode costs a core, whatever else the
// machine runs meanwhile (wall time on a shared 2-core machine is mostly
// the other processes' turns).
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

struct Candidate {
  std::string name;
  std::function<std::vector<std::uint8_t>(const Image&)> encode;
  FrameFormat format;  // how to decode it for the check
};

std::vector<Candidate> candidates() {
  auto libpng = [](int level, int filters) {
    return [=](const Image& img) { return encode_png(img, level, filters); };
  };
  auto deflate = [](int level, PngRowFilter f) {
    return [=](const Image& img) { return encode_png_libdeflate(img, level, f); };
  };
  auto raw = [](FrameFormat f, int level) {
    return [=](const Image& img) { return encode_raw_frame(img.rgb, img.bit_depth, f, level); };
  };
  return {
      {"libpng z2 sub (old default)", libpng(2, 0x10), FrameFormat::kPng},
      {"libpng z1 sub", libpng(1, 0x10), FrameFormat::kPng},
      {"libpng z1 up", libpng(1, 0x20), FrameFormat::kPng},
      {"libdeflate 1 none", deflate(1, PngRowFilter::kNone), FrameFormat::kPng},
      {"libdeflate 1 sub", deflate(1, PngRowFilter::kSub), FrameFormat::kPng},
      {"libdeflate 1 up", deflate(1, PngRowFilter::kUp), FrameFormat::kPng},
      {"libdeflate 2 sub", deflate(2, PngRowFilter::kSub), FrameFormat::kPng},
      {"libdeflate 4 sub", deflate(4, PngRowFilter::kSub), FrameFormat::kPng},
      {"raw", raw(FrameFormat::kRaw, 0), FrameFormat::kRaw},
      {"raw_zstd 1", raw(FrameFormat::kRawZstd, 1), FrameFormat::kRawZstd},
      {"raw_zstd 3", raw(FrameFormat::kRawZstd, 3), FrameFormat::kRawZstd},
  };
}

bool same_samples(const Candidate& c, const std::vector<std::uint8_t>& bytes, const Image& img) {
  if (c.format == FrameFormat::kPng) {
    const Image back = decode_png(bytes);
    return back.width == img.width && back.height == img.height &&
           back.bit_depth == img.bit_depth && back.rgb == img.rgb;
  }
  return decode_raw_frame(bytes, img.width, img.height, img.bit_depth, c.format) == img.rgb;
}

}  // namespace

int main(int argc, char** argv) {
  double min_ms = 300.0;
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--min-ms" && i + 1 < argc) {
      min_ms = std::atof(argv[++i]);
    } else if (std::filesystem::is_directory(a)) {
      for (const auto& e : std::filesystem::recursive_directory_iterator(a)) {
        if (e.path().extension() == ".png") files.push_back(e.path());
      }
    } else {
      std::fprintf(stderr, "usage: beamcast_bench_png [--min-ms MS] DIR...\n");
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  const auto cands = candidates();
  // Per frame and candidate: the least CPU time of repeated encodes and the size.
  struct Row {
    double raw_bytes = 0.0;
    std::vector<std::pair<double, std::size_t>> runs;  // (fastest ms, bytes) per candidate
  };
  std::map<std::string, Row> rows;
  std::vector<double> total_ms(cands.size(), 0.0), total_bytes(cands.size(), 0.0);
  double total_raw = 0.0;
  for (const auto& f : files) {
    const Image img = read_png(f);
    const double raw_bytes = 3.0 * img.width * img.height * (img.bit_depth / 8);
    total_raw += raw_bytes;
    const std::string name = f.parent_path().filename().string() + "/" + f.stem().string() + " (" +
                             std::to_string(img.width) + "x" + std::to_string(img.height) + ", " +
                             std::to_string(img.bit_depth) + "-bit)";
    for (std::size_t k = 0; k < cands.size(); ++k) {
      std::vector<std::uint8_t> bytes = cands[k].encode(img);
      if (!same_samples(cands[k], bytes, img)) {
        std::fprintf(stderr, "%s: %s does not decode to the same samples\n", name.c_str(),
                     cands[k].name.c_str());
        return 1;
      }
      double best = 1e30, spent = 0.0;
      for (int rep = 0; rep < 200 && (rep < 3 || spent < min_ms); ++rep) {
        const double t0 = thread_cpu_ms();
        bytes = cands[k].encode(img);
        const double ms = thread_cpu_ms() - t0;
        best = std::min(best, ms);
        spent += ms;
      }
      rows[name].raw_bytes = raw_bytes;
      rows[name].runs.push_back({best, bytes.size()});
      total_ms[k] += best;
      total_bytes[k] += static_cast<double>(bytes.size());
    }
  }
  for (int table = 0; table < 2; ++table) {
    std::printf("\n%s\n\n| frame |", table == 0 ? "MB/s (raw RGB bytes / CPU time of the encode, one core)"
                                             : "bytes (KB)");
    for (const auto& c : cands) std::printf(" %s |", c.name.c_str());
    std::printf("\n|---|");
    for (std::size_t k = 0; k < cands.size(); ++k) std::printf("---|");
    std::printf("\n");
    for (const auto& [name, r] : rows) {
      std::printf("| %s |", name.c_str());
      for (std::size_t k = 0; k < cands.size(); ++k) {
        if (table == 0) {
          std::printf(" %.0f |", r.raw_bytes / 1e6 / (r.runs[k].first / 1e3));
        } else {
          std::printf(" %.1f |", static_cast<double>(r.runs[k].second) / 1024.0);
        }
      }
      std::printf("\n");
    }
    std::printf("| **all frames** |");
    for (std::size_t k = 0; k < cands.size(); ++k) {
      if (table == 0) {
        std::printf(" **%.0f** |", total_raw / 1e6 / (total_ms[k] / 1e3));
      } else {
        std::printf(" **%.0f** |", total_bytes[k] / 1024.0);
      }
    }
    std::printf("\n");
  }
  return 0;
}
