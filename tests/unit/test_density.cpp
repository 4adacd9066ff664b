// Radial density functions (protocol/density.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "protocol/density.hpp"
#include "tests/unit/test_densities.hpp"

namespace beamcast {
namespace {

using testing_support::named;

std::vector<Density> all_kinds() {
  std::vector<Density> v;
  for (const char* n : {"abe", "shell", "linear", "quadratic", "gaussian"}) v.push_back(named(n));
  Density t;
  t.kind = DensityKind::kTable;
  t.samples = {2, 1, 0.5, 0.25, 0.1};
  v.push_back(t);
  return v;
}

TEST(Density, AbeKeyPoints) {
  const Density d = named("abe");
  EXPECT_EQ(d(0.0), 99.0);
  EXPECT_EQ(d(0.01), 99.0);
  EXPECT_DOUBLE_EQ(d(0.5), 1.0);  // 1/x - 1
  EXPECT_DOUBLE_EQ(d(0.25), 3.0);
  EXPECT_EQ(d.max_value(), 99.0);
}

TEST(Density, ShellKeyPoints) {
  const Density d = named("shell");
  EXPECT_DOUBLE_EQ(d(0.8), 5.0);
  EXPECT_EQ(d(0.7), 0.0);
  EXPECT_EQ(d(0.9), 0.0);
  EXPECT_NEAR(d(0.78), 3.0, 1e-12);
  EXPECT_EQ(d(0.0), 0.0);
}

TEST(Density, SimpleKinds) {
  EXPECT_DOUBLE_EQ(named("linear")(0.25), 0.75);
  EXPECT_DOUBLE_EQ(named("quadratic")(0.5), 0.75);
  EXPECT_DOUBLE_EQ(named("gaussian")(0.0), 1.0);
  Density g = named("gaussian");
  g.sigma = 0.5;
  EXPECT_DOUBLE_EQ(g(0.5), std::exp(-0.5));
}

TEST(Density, TableInterpolatesLinearly) {
  Density t;
  t.kind = DensityKind::kTable;
  t.samples = {1, 3, 0};
  EXPECT_DOUBLE_EQ(t(0.0), 1.0);
  EXPECT_DOUBLE_EQ(t(0.25), 2.0);
  EXPECT_DOUBLE_EQ(t(0.5), 3.0);
  EXPECT_DOUBLE_EQ(t(0.75), 1.5);
  EXPECT_EQ(t.max_value(), 3.0);
}

TEST(Density, ZeroAtAndBeyondOneAndBelowZero) {
  for (const Density& d : all_kinds()) {
    for (double x : {1.0, 1.0000001, 1.5, 10.0, 1e300})
      EXPECT_EQ(d(x), 0.0) << d.name() << " " << x;
    EXPECT_EQ(d(-0.1), 0.0) << d.name();
    EXPECT_EQ(d(std::nan("")), 0.0) << d.name();
  }
}

TEST(Density, MaxValueBoundsSamples) {
  for (const Density& d : all_kinds()) {
    for (int i = 0; i < 1000; ++i) EXPECT_LE(d(i / 1000.0), d.max_value()) << d.name();
  }
}

TEST(Density, BreakpointsSortedEndingInOne) {
  for (const Density& d : all_kinds()) {
    const auto b = d.breakpoints();
    ASSERT_FALSE(b.empty()) << d.name();
    EXPECT_TRUE(std::is_sorted(b.begin(), b.end())) << d.name();
    EXPECT_EQ(b.back(), 1.0) << d.name();
    EXPECT_GT(b.front(), 0.0) << d.name();
  }
}

TEST(Density, KeyDistinguishesParameters) {
  Density a = named("gaussian");
  Density b = a;
  b.sigma = 0.41;
  EXPECT_NE(a.key(), b.key());
  EXPECT_EQ(a.key(), named("gaussian").key());
  Density t1;
  t1.kind = DensityKind::kTable;
  t1.samples = {1, 0};
  Density t2 = t1;
  t2.samples = {1, 0.5};
  EXPECT_NE(t1.key(), t2.key());
  EXPECT_NE(named("abe").key(), named("shell").key());
}

TEST(Density, UnknownNameRejected) {
  Density d;
  EXPECT_FALSE(density_from_name("cubic", &d));
  EXPECT_FALSE(density_from_name("", &d));
}

}  // namespace
}  // namespace beamcast
