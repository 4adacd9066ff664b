// The load generator's latency histogram against exact order statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "client/latency_histogram.hpp"

namespace beamcast::client {
namespace {

TEST(LatencyHistogram, BucketsTileTheRangeWithoutGaps) {
  // Every value maps to a bucket whose upper edge is >= the value, and the
  // previous bucket's edge is below it (no gaps, no overlaps).
  for (std::uint64_t v : {0ull, 1ull, 63ull, 64ull, 65ull, 127ull, 128ull, 1000ull, 123456ull,
                          (1ull << 39) + 12345ull}) {
    const std::size_t i = LatencyHistogram::index_of(v);
    EXPECT_GE(LatencyHistogram::upper_edge(i), v) << v;
    if (i > 0) EXPECT_LT(LatencyHistogram::upper_edge(i - 1), v) << v;
  }
  for (std::uint64_t v = 0; v < 100000; ++v) {
    ASSERT_EQ(LatencyHistogram::index_of(v) == LatencyHistogram::index_of(v + 1),
              LatencyHistogram::upper_edge(LatencyHistogram::index_of(v)) > v)
        << v;
  }
}

TEST(LatencyHistogram, PercentilesWithinOneBucketOfExact) {
  std::mt19937_64 rng(7);
  std::lognormal_distribution<double> dist(2.0, 1.2);  // ms; a long tail like real latency
  LatencyHistogram h;
  std::vector<std::uint64_t> exact;
  for (int i = 0; i < 200000; ++i) {
    const double ms = dist(rng);
    h.record_ms(ms);
    exact.push_back(static_cast<std::uint64_t>(ms * 1000.0));
  }
  std::sort(exact.begin(), exact.end());
  for (double q : {0.5, 0.9, 0.99, 0.999, 1.0}) {
    const std::size_t rank = static_cast<std::size_t>(std::ceil(q * exact.size()));
    const double truth = static_cast<double>(exact[rank - 1]) / 1000.0;
    const double got = h.percentile_ms(q);
    // Never below the true order statistic, at most one bucket width (1/64 of
    // the value) above it: the layout's stated resolution.
    EXPECT_GE(got, truth) << q;
    EXPECT_LE(got, truth * (1.0 + 1.0 / 64.0) + 0.001) << q;
  }
  EXPECT_DOUBLE_EQ(h.percentile_ms(1.0), h.max_ms());
}

TEST(LatencyHistogram, MergeEqualsRecordingIntoOne) {
  LatencyHistogram a, b, all;
  for (int i = 1; i <= 1000; ++i) {
    (i % 3 ? a : b).record_ms(i * 0.37);
    all.record_ms(i * 0.37);
  }
  a.merge(b);
  EXPECT_EQ(a.count(), all.count());
  for (double q : {0.1, 0.5, 0.99}) EXPECT_EQ(a.percentile_ms(q), all.percentile_ms(q));
  EXPECT_EQ(a.max_ms(), all.max_ms());
  EXPECT_NEAR(a.mean_ms(), all.mean_ms(), 1e-9);
}

TEST(LatencyHistogram, EmptyReportsZero) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile_ms(0.99), 0.0);
  EXPECT_EQ(h.max_ms(), 0.0);
}

}  // namespace
}  // namespace beamcast::client
