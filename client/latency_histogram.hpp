// A log-linear latency histogram (the HdrHistogram layout, simplified): values
// in microseconds; each power-of-two range [2^k, 2^(k+1)) is split into
// kSubBuckets equal buckets, so a bucket's width is at most 1/kSubBuckets of
// its lower bound. A percentile is reported as the upper edge of its bucket:
// at most 1/64 = 1.6 % above the true value, never below it. Values 0..63 us
// are exact. Covers 1 us .. 2^40 us (12.7 days); larger values are clamped.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "protocol/check.hpp"

namespace beamcast::client {

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 6;
  static constexpr std::uint64_t kSubBuckets = 1u << kSubBits;  // 64
  static constexpr int kMaxExp = 40;

  void record_ms(double ms) { record_us(ms <= 0 ? 0 : static_cast<std::uint64_t>(ms * 1000.0)); }
  void record_us(std::uint64_t us) {
    us = std::min<std::uint64_t>(us, (std::uint64_t{1} << kMaxExp) - 1);
    BEAMCAST_DCHECK(index_of(us) < counts_.size(), "latency bucket out of range");
    ++counts_[index_of(us)];
    ++count_;
    max_us_ = std::max(max_us_, us);
    min_us_ = std::min(min_us_, us);
    sum_us_ += static_cast<double>(us);
  }
  void merge(const LatencyHistogram& o) {
    for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += o.counts_[i];
    count_ += o.count_;
    max_us_ = std::max(max_us_, o.max_us_);
    min_us_ = std::min(min_us_, o.min_us_);
    sum_us_ += o.sum_us_;
  }
  std::uint64_t count() const { return count_; }
  double max_ms() const { return count_ ? static_cast<double>(max_us_) / 1000.0 : 0.0; }
  double min_ms() const { return count_ ? static_cast<double>(min_us_) / 1000.0 : 0.0; }
  double mean_ms() const { return count_ ? sum_us_ / static_cast<double>(count_) / 1000.0 : 0.0; }

  // The q-quantile (0 < q <= 1): the upper edge of the bucket holding the
  // ceil(q * count)-th smallest value, capped at the exact maximum.
  double percentile_ms(double q) const {
    if (count_ == 0) return 0.0;
    const auto rank = static_cast<std::uint64_t>(
        std::max(1.0, std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_))));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < counts_.size(); ++i) {
      seen += counts_[i];
      if (seen >= rank) return static_cast<double>(std::min(upper_edge(i), max_us_)) / 1000.0;
    }
    return max_ms();
  }

  // Bucket index and its inclusive upper edge (exposed for tests).
  static std::size_t index_of(std::uint64_t us) {
    if (us < kSubBuckets) return static_cast<std::size_t>(us);
    const int e = std::bit_width(us) - 1;  // us in [2^e, 2^(e+1)), e >= kSubBits
    const std::uint64_t sub = (us >> (e - kSubBits)) - kSubBuckets;  // 0..63
    return static_cast<std::size_t>(kSubBuckets * (e - kSubBits + 1) + sub);
  }
  static std::uint64_t upper_edge(std::size_t index) {
    if (index < kSubBuckets) return index;
    const int e = static_cast<int>(index / kSubBuckets) + kSubBits - 1;
    const std::uint64_t sub = index % kSubBuckets;
    return ((kSubBuckets + sub + 1) << (e - kSubBits)) - 1;
  }

 private:
  static constexpr std::size_t kBuckets = kSubBuckets * (kMaxExp - kSubBits + 1);
  std::array<std::uint64_t, kBuckets> counts_{};
  std::uint64_t count_ = 0;
  std::uint64_t max_us_ = 0;
  std::uint64_t min_us_ = ~std::uint64_t{0};
  double sum_us_ = 0.0;
};

}  // namespace beamcast::client
