// Progress on stderr for long batch jobs, and a summary of per-frame times.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace beamcast::cli {

// A bar redrawn in place ("\r") when stderr is a terminal; otherwise one plain
// line per update ("frames 12/36 (33%), 1.4 s"), or with `min_interval_s`
// at most one per that many seconds between the first and the last, so logs
// stay readable.
class ProgressBar {
 public:
  ProgressBar(int total, std::string what, std::FILE* out = stderr, double min_interval_s = 0.0);
  void update(int done);
  void finish();  // ends the bar's line (terminal) or prints the last line

 private:
  int total_;
  int last_ = -1;
  std::string what_;
  std::FILE* out_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
  double min_interval_s_;
  double printed_s_ = -1e9;  // when the last plain line was printed
};

struct TimeSummary {
  double mean = 0.0, p50 = 0.0, max = 0.0;
};
// Empty input: all zero. p50 is the median (mean of the middle two for even n).
TimeSummary summarize(std::vector<double> values);

}  // namespace beamcast::cli
