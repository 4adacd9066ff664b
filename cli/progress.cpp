#include "cli/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <numeric>

namespace beamcast::cli {

ProgressBar::ProgressBar(int total, std::string what, std::FILE* out, double min_interval_s)
    : total_(std::max(total, 1)),
      what_(std::move(what)),
      out_(out),
      tty_(isatty(fileno(out)) == 1),
      start_(std::chrono::steady_clock::now()),
      min_interval_s_(min_interval_s) {}

void ProgressBar::update(int done) {
  if (done == last_) return;
  last_ = done;
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double frac = static_cast<double>(done) / total_;
  if (!tty_) {
    if (done > 0 && done < total_ && s - printed_s_ < min_interval_s_) return;
    printed_s_ = s;
    std::fprintf(out_, "%s %d/%d (%.0f%%), %.1f s\n", what_.c_str(), done, total_, 100 * frac, s);
    std::fflush(out_);
    return;
  }
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(frac * kWidth + 0.5);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '-');
  const double eta = done > 0 ? s / done * (total_ - done) : 0.0;
  std::fprintf(out_, "\r[%s] %d/%d %s  %.1f s  eta %.1f s ", bar.c_str(), done, total_,
               what_.c_str(), s, eta);
  std::fflush(out_);
}

void ProgressBar::finish() {
  if (tty_) {
    std::fprintf(out_, "\n");
    std::fflush(out_);
  }
}

TimeSummary summarize(std::vector<double> v) {
  TimeSummary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  const std::size_t n = v.size();
  s.p50 = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.max = v.back();
  return s;
}

}  // namespace beamcast::cli
