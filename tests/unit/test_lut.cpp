// Line integrals g(d, s) and the tables built from them.
//
// Closed forms are written with tau = t - 1 measured from the closest approach
// and u = sqrt(d^2 + tau^2); the integrand vanishes outside the chord
// |tau| <= c = sqrt(1 - d^2), so g(d, s) = G(clip(s - 1)) - G(clip(-1)) with
// G the antiderivative that is 0 at tau = 0 (odd in tau).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "protocol/density.hpp"
#include "tests/unit/test_densities.hpp"
#include "render/lut.hpp"
#include "render/quadrature.hpp"

namespace beamcast {
namespace {

using testing_support::named;

Density gaussian(double sigma) {
  Density d = named("gaussian");
  d.sigma = sigma;
  return d;
}

// ln((a + sqrt(a^2 + d^2)) / (b + sqrt(b^2 + d^2))) = asinh(a/d) - asinh(b/d) for
// a, b > 0; finite also at d = 0.
double asinh_diff(double a, double b, double d) {
  return std::log((a + std::sqrt(a * a + d * d)) / (b + std::sqrt(b * b + d * d)));
}

// Antiderivatives G(tau), odd, G(0) = 0, valid for |tau| <= sqrt(1 - d^2).
double g_linear(double d, double tau) {
  const double a = std::abs(tau);
  const double u = std::sqrt(d * d + a * a);
  const double as = d > 0.0 ? d * d * std::asinh(a / d) : 0.0;
  return std::copysign(a - 0.5 * (a * u + as), tau);
}
double g_quadratic(double d, double tau) { return tau * (1.0 - d * d) - tau * tau * tau / 3.0; }
double g_abe(double d, double tau) {
  const double a = std::abs(tau);
  const double core = 0.01;
  double v;
  if (d >= core) {  // the ray never enters the constant core: asinh(a/d) - a
    v = d > 0.0 ? std::asinh(a / d) - a : 0.0;
  } else {
    const double tc = std::sqrt((core - d) * (core + d));  // half chord of the core
    if (a <= tc) {
      v = 99.0 * a;
    } else {
      v = 99.0 * tc + asinh_diff(a, tc, d) - (a - tc);
    }
  }
  return std::copysign(v, tau);
}
double g_gaussian(double sigma, double d, double tau) {
  return std::exp(-d * d / (2 * sigma * sigma)) * sigma * std::sqrt(std::numbers::pi / 2) *
         std::erf(tau / (sigma * std::numbers::sqrt2));
}

template <class G>
double closed_form(G&& G_, double d, double s) {
  if (d >= 1.0) return 0.0;
  const double c = std::sqrt((1.0 - d) * (1.0 + d));
  const double hi = std::clamp(s - 1.0, -c, c);
  const double lo = std::clamp(-1.0, -c, c);
  return G_(d, hi) - G_(d, lo);
}

std::vector<double> d_sweep() {
  return {0.0, 1e-9, 1e-6, 1e-3, 0.005, 0.00999, 0.01, 0.01001, 0.05, 0.1, 0.2, 0.3333,
          0.5, 0.7, 0.75, 0.7999, 0.8, 0.8001, 0.85, 0.9, 0.99, 0.999999, 1.0 - 1e-12, 1.0};
}
std::vector<double> s_sweep() {
  return {0.0, 1e-9, 0.001, 0.1, 0.3, 0.5, 0.9, 0.999, 1.0, 1.001, 1.2, 1.5, 1.9, 1.999999, 2.0};
}

// Quadrature target is 1e-12 relative (lut.hpp). The closed forms lose a few
// ulps of their largest term (asinh, erf and the cancellation in
// tau - (tau u + d^2 asinh) / 2 near d -> 1), so the comparison allows 1e-11
// relative plus 1e-14 absolute (values are O(1) at most; 1e-14 is ~50 ulps of 1).
void expect_close(double got, double want, const char* what, double d, double s) {
  EXPECT_NEAR(got, want, 1e-11 * std::abs(want) + 1e-14) << what << " d=" << d << " s=" << s;
}

TEST(LineIntegral, LinearClosedForm) {
  const Density f = named("linear");
  for (double d : d_sweep())
    for (double s : s_sweep())
      expect_close(line_integral(f, d, s), closed_form(g_linear, d, s), "linear", d, s);
}

TEST(LineIntegral, QuadraticClosedForm) {
  const Density f = named("quadratic");
  for (double d : d_sweep())
    for (double s : s_sweep())
      expect_close(line_integral(f, d, s), closed_form(g_quadratic, d, s), "quadratic", d, s);
}

TEST(LineIntegral, AbeClosedFormWithCore) {
  const Density f = named("abe");
  for (double d : d_sweep())
    for (double s : s_sweep())
      expect_close(line_integral(f, d, s), closed_form(g_abe, d, s), "abe", d, s);
}

TEST(LineIntegral, GaussianClosedForm) {
  for (double sigma : {0.1, 0.4, 2.0}) {
    const Density f = gaussian(sigma);
    auto G = [sigma](double d, double tau) { return g_gaussian(sigma, d, tau); };
    for (double d : d_sweep())
      for (double s : s_sweep()) expect_close(line_integral(f, d, s), closed_form(G, d, s), "gauss", d, s);
  }
}

// Independent check for the shell (no closed form): composite Simpson with
// 2^20 panels on each piece between the t where the distance crosses a
// breakpoint (computed here from scratch). Simpson's error on these smooth
// pieces is ~h^4 |f''''| with h <= 2e-6: far below 1e-12.
double simpson_shell(const Density& f, double d, double s) {
  if (d >= 1.0 || s <= 0.0) return 0.0;
  std::vector<double> cuts = {0.0, s, 1.0};
  for (double x : {0.75, 0.8, 0.85, 1.0}) {
    if (x > d) {
      cuts.push_back(1.0 - std::sqrt(x * x - d * d));
      cuts.push_back(1.0 + std::sqrt(x * x - d * d));
    }
  }
  std::sort(cuts.begin(), cuts.end());
  double total = 0.0;
  const int n = 1 << 20;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = std::max(cuts[k], 0.0);
    const double b = std::min(cuts[k + 1], s);
    if (!(b > a)) continue;
    auto F = [&](double t) { return f(std::sqrt(d * d + (t - 1) * (t - 1))); };
    // Skip pieces where the integrand is identically zero (cheap: most of them).
    if (F(a + 0.25 * (b - a)) == 0.0 && F(0.5 * (a + b)) == 0.0 && F(a + 0.75 * (b - a)) == 0.0)
      continue;
    const double h = (b - a) / n;
    double sum = F(a + 1e-15 * (b - a)) + F(b - 1e-15 * (b - a));  // one-sided at the ends
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * F(a + i * h);
    total += sum * h / 3.0;
  }
  return total;
}

TEST(LineIntegral, ShellAgainstDenseSimpson) {
  const Density f = named("shell");
  for (double d : {0.0, 0.3, 0.76, 0.8, 0.82, 0.8499})
    for (double s : {0.19, 0.5, 1.0, 1.3, 2.0}) {
      // Simpson with h ~ 1e-7..1e-6 on kinks-free pieces is good to ~1e-13;
      // 1e-10 relative leaves room for the summation of 2^20 terms (~1e-13).
      const double want = simpson_shell(f, d, s);
      EXPECT_NEAR(line_integral(f, d, s), want, 1e-10 * std::abs(want) + 1e-14)
          << "d=" << d << " s=" << s;
    }
}

TEST(LineIntegral, AdditiveAndSymmetric) {
  for (const char* name : {"abe", "shell", "linear", "quadratic", "gaussian"}) {
    const Density f = named(name);
    for (double d : d_sweep()) {
      const double g1 = line_integral(f, d, 1.0);
      // f depends on |t - 1| only: the two halves of the chord are equal.
      // Two independent integrations agree to their 1e-12 target; 1e-11 relative.
      EXPECT_NEAR(line_integral(f, d, 2.0), 2.0 * g1, 1e-11 * g1 + 1e-15) << name << " d=" << d;
      EXPECT_EQ(line_integral(f, d, 0.0), 0.0);
      // Additivity over the table's sub-intervals: sum of g over pieces.
      double sum = 0.0;
      for (int k = 0; k < 7; ++k) {
        const double a = 2.0 * k / 7.0;
        const double b = 2.0 * (k + 1) / 7.0;
        sum += line_integral(f, d, b) - line_integral(f, d, a);
      }
      EXPECT_NEAR(sum, 2.0 * g1, 1e-11 * g1 + 1e-15) << name << " d=" << d;
    }
  }
}

TEST(BuildTable, MatchesLineIntegralAtGridPoints) {
  for (const char* name : {"abe", "shell", "linear", "gaussian"}) {
    const Density f = named(name);
    const int nd = 33;
    const int ns = 65;
    const LineIntegralTable t = build_table(f, nd, ns, 17);
    ASSERT_EQ(t.nd, nd);
    ASSERT_EQ(t.ns, ns);
    ASSERT_EQ(t.g.size(), static_cast<std::size_t>(nd * ns));
    for (int i = 0; i < nd; ++i) {
      const double d = static_cast<double>(i) / (nd - 1);
      EXPECT_EQ(t.g[i * ns], 0.0f);  // g(d, 0) = 0
      for (int j = 0; j < ns; ++j) {
        const double s = 2.0 * j / (ns - 1);
        const double want = line_integral(f, d, s);
        // Stored as float: half an ulp is 2^-24 relative (6e-8); the cumulative
        // double sum adds ~1e-12. 1e-7 relative covers both.
        EXPECT_NEAR(t.g[i * ns + j], want, 1e-7 * std::abs(want) + 1e-12)
            << name << " i=" << i << " j=" << j;
        if (j > 0) {
          EXPECT_GE(t.g[i * ns + j], t.g[i * ns + j - 1]);  // f >= 0: monotone in s
        }
      }
      // Symmetry of the chord: g(d, 2) = 2 g(d, 1) (s = 1 is column (ns-1)/2);
      // two float roundings of values of the same size: 2^-23 relative.
      const double g1 = t.g[i * ns + (ns - 1) / 2];
      EXPECT_NEAR(t.g[i * ns + ns - 1], 2.0 * g1, 2.5e-7 * g1 + 1e-12) << name << " i=" << i;
    }
  }
}

TEST(BuildTable, FTableKeepsLeftLimitAtTheCut) {
  const Density f = gaussian(0.4);
  const LineIntegralTable t = build_table(f, 2, 2, 11);
  ASSERT_EQ(t.f.size(), 11u);
  for (int k = 0; k < 10; ++k) EXPECT_FLOAT_EQ(t.f[k], static_cast<float>(f(k / 10.0)));
  // f(1) = 0 but the last sample holds the left limit exp(-1 / (2 sigma^2)).
  EXPECT_FLOAT_EQ(t.f[10], static_cast<float>(std::exp(-1.0 / (2 * 0.4 * 0.4))));
  const LineIntegralTable a = build_table(named("abe"), 2, 2, 101);
  EXPECT_FLOAT_EQ(a.f[0], 99.0f);
  EXPECT_FLOAT_EQ(a.f[50], 1.0f);  // 1/0.5 - 1
  EXPECT_NEAR(a.f[100], 0.0f, 1e-11);  // 1/(1-1e-12) - 1: continuous at the cut
}

TEST(BuildTable, RejectsBadSizes) {
  const Density f = named("linear");
  EXPECT_THROW(build_table(f, 1, 16, 16), std::invalid_argument);
  EXPECT_THROW(build_table(f, 16, 4097, 16), std::invalid_argument);
  EXPECT_THROW(build_table(f, 16, 16, 0), std::invalid_argument);
  EXPECT_NO_THROW(build_table(f, 2, 2, 2));
}

TEST(BuildTable, TabulatedDensity) {
  // A user table (piecewise linear, kinks at every sample) against Simpson-free
  // reference: for a hat function f = 1 - x the table density equals linear.
  Density tab;
  tab.kind = DensityKind::kTable;
  for (int i = 0; i <= 8; ++i) tab.samples.push_back(1.0 - i / 8.0);
  for (double d : {0.0, 0.2, 0.6, 0.95})
    for (double s : {0.5, 1.0, 2.0})
      expect_close(line_integral(tab, d, s), closed_form(g_linear, d, s), "table", d, s);
}

TEST(Quadrature, AdaptiveHandlesNearSingularIntegrands) {
  // sqrt(x) on [0, 1]: endpoint singularity of the derivative; exact 2/3.
  // The estimate is requested at 1e-12 relative; 1e-11 allows the error
  // estimator's own slack.
  quad::Options opt;
  opt.rel_tol = 1e-12;
  const auto r = quad::integrate([](double x) { return std::sqrt(x); }, 0.0, 1.0, opt);
  EXPECT_NEAR(r.value, 2.0 / 3.0, 1e-11);
  // A polynomial of degree <= 13 is integrated exactly by both the G7 and the
  // K15 rule, so the error estimate is at rounding level and one rule suffices
  // (1e-15: a few ulps of the result).
  const auto p = quad::integrate([](double x) { return std::pow(x, 12); }, -1.0, 1.0, opt);
  EXPECT_NEAR(p.value, 2.0 / 13.0, 1e-15);
  EXPECT_EQ(p.intervals, 1);
}

}  // namespace
}  // namespace beamcast
