// The chord and warped table layouts hold exactly g at their own grid points.
#include <gtest/gtest.h>

#include <cmath>

#include "render/lut.hpp"
#include "tests/unit/test_densities.hpp"

namespace beamcast {
namespace {

using testing_support::named;

// Entries are g in double rounded to float: relative 2^-24 ~ 6e-8 of the
// largest value in the table, plus the quadrature's 1e-12, so 1e-6 of the
// table's maximum is a safe bound that still catches a misplaced row or column
// (one row or column off changes entries by ~1e-2 at these sizes).
void expect_entries_match(const Density& density, TableLayout layout) {
  const int nd = 33, ns = 17;
  const LineIntegralTable t = build_table(density, nd, ns, 64, layout);
  const std::vector<double> rows = table_rows(t);
  float gmax = 0.0f;
  for (float v : t.g) gmax = std::max(gmax, v);
  const bool chord = layout == TableLayout::kChord || layout == TableLayout::kChordWarped;
  for (int i = 0; i < nd; ++i) {
    const double d = rows[i];
    const double c = d < 1.0 ? std::sqrt((1.0 - d) * (1.0 + d)) : 0.0;
    for (int j = 0; j < ns; ++j) {
      const double u = static_cast<double>(j) / (ns - 1);
      const double s = chord ? 1.0 + (2.0 * u - 1.0) * c : 2.0 * u;
      EXPECT_NEAR(t.g[i * ns + j], line_integral(density, d, s), 1e-6 * gmax)
          << density.name() << " row " << i << " (d=" << d << ") column " << j;
    }
  }
}

TEST(TableLayouts, EveryLayoutHoldsGAtItsGridPoints) {
  for (const char* name : {"abe", "shell", "linear", "gaussian"}) {
    for (TableLayout layout : {TableLayout::kUniform, TableLayout::kChord, TableLayout::kWarped,
                               TableLayout::kChordWarped}) {
      expect_entries_match(named(name), layout);
    }
  }
}

TEST(TableLayouts, WarpIsMonotoneAndConcentratesRowsAtTheShell) {
  const LineIntegralTable t = build_table(named("shell"), 64, 16, 64, TableLayout::kWarped);
  ASSERT_EQ(static_cast<int>(t.warp.size()), t.nw);
  EXPECT_FLOAT_EQ(t.warp.front(), 0.0f);
  EXPECT_FLOAT_EQ(t.warp.back(), 1.0f);
  for (int m = 1; m < t.nw; ++m) EXPECT_GT(t.warp[m], t.warp[m - 1]);
  // The shell lives at 0.75 < x < 0.85: g varies fastest in d there, so more
  // rows than the uniform share (10% of them) must fall in that band.
  int in_band = 0;
  for (double d : table_rows(t)) in_band += (d > 0.74 && d < 0.86);
  EXPECT_GT(in_band, 64 * 0.12 * 2);
}

TEST(TableLayouts, UniformLayoutHasNoWarp) {
  const LineIntegralTable t = build_table(named("abe"), 16, 16, 64, TableLayout::kChord);
  EXPECT_TRUE(t.warp.empty());
  const std::vector<double> rows = table_rows(t);
  EXPECT_DOUBLE_EQ(rows[5], 5.0 / 15.0);
}

}  // namespace
}  // namespace beamcast
