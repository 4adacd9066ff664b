#include "render/beam_medium.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "render/quadrature.hpp"

namespace beamcast {

namespace {

// The integral of f(sqrt(d^2 + s^2) / r) g(s) over |s| <= h: twice the
// half chord (the integrand is even), split where the radius x = sqrt(d^2
// + s^2) / r crosses a breakpoint of f.
template <class G>
double chord_integral(const Density& f, double r, double d, G g) {
  const double h = std::sqrt(std::max(0.0, r * r - d * d));
  std::vector<double> pts{0.0};
  for (double x : f.breakpoints()) {
    const double s2 = x * x * r * r - d * d;
    if (s2 > 0.0 && std::sqrt(s2) < h) pts.push_back(std::sqrt(s2));
  }
  pts.push_back(h);
  auto integrand = [&](double s) { return f(std::sqrt(d * d + s * s) / r) * g(s); };
  return 2.0 * quad::integrate_pieces(integrand, pts.data(), pts.size()).value;
}

// The integral of f(sqrt(d^2 + tau^2)) g(tau) over [a, b] (d, tau in units
// of the radius), split at the chord's midpoint and where the radius crosses
// a breakpoint of f.
template <class G>
double piece_integral(const Density& f, double d, double a, double b, G g) {
  const double h = std::sqrt(std::max(0.0, (1.0 - d) * (1.0 + d)));
  const double lo = std::max(a, -h), hi = std::min(b, h);
  if (!(hi > lo)) return 0.0;
  std::vector<double> pts{lo};
  auto inside = [&](double x) {
    if (x > lo && x < hi) pts.push_back(x);
  };
  inside(0.0);
  for (double x : f.breakpoints()) {
    if (x > d && x < 1.0) {
      const double s = std::sqrt((x - d) * (x + d));
      inside(-s);
      inside(s);
    }
  }
  pts.push_back(hi);
  std::sort(pts.begin(), pts.end());
  auto integrand = [&](double t) { return f(std::sqrt(d * d + t * t)) * g(t); };
  quad::Options opt;
  opt.rel_tol = 1e-12;
  opt.abs_tol = 1e-16;
  return quad::integrate_pieces(integrand, pts.data(), pts.size(), opt).value;
}

}  // namespace

double beam_piece_exact(const Density& f, double d, double a, double b, double kappa) {
  return piece_integral(f, d, a, b, [=](double t) { return std::exp(-kappa * (t - a)); });
}

std::array<double, 4> piece_moments(const Density& f, double d, double a, double b) {
  std::array<double, 4> m{};
  for (int n = 0; n < 4; ++n) {
    m[static_cast<std::size_t>(n)] =
        piece_integral(f, d, a, b, [n](double t) { return std::pow(t, n); });
  }
  return m;
}

DensityGauss2 density_gauss2(const std::array<double, 4>& m, double a, double b) {
  DensityGauss2 r;
  const double mean = std::clamp(m[1] / m[0], a, b);
  r.x[0] = r.x[1] = mean;
  r.w[0] = r.w[1] = 0.5 * m[0];
  const double e2 = m[2] / m[0], e3 = m[3] / m[0];
  const double var = std::clamp(e2 - mean * mean, 0.0, (b - mean) * (mean - a));
  if (!(var > 1e-6 * (b - a) * (b - a))) return r;
  // Nodes mean + y with y^2 - (k3 / var) y - var = 0: the two-point
  // distribution with f's mean, variance and third central moment k3.
  const double k3 = e3 - 3.0 * mean * e2 + 2.0 * mean * mean * mean;
  const double p = 0.5 * k3 / var;
  const double q = std::sqrt(p * p + var);
  r.x[0] = std::clamp(mean + p - q, a, mean);
  r.x[1] = std::clamp(mean + p + q, mean, b);
  if (r.x[1] > r.x[0]) {
    const double w0 = (r.x[1] - mean) / (r.x[1] - r.x[0]);
    r.w[0] = m[0] * w0;
    r.w[1] = m[0] * (1.0 - w0);
  }
  return r;
}

double beam_piece_rule(const Density& f, double d, double a, double b, double kappa,
                       BeamMediumRule rule, double step) {
  const double h = std::sqrt(std::max(0.0, (1.0 - d) * (1.0 + d)));
  const double lo = std::max(a, -h), hi = std::min(b, h);
  if (!(hi > lo)) return 0.0;
  const double shift = lo - a;  // attenuation from a to the chord
  const double len = kappa > 0.0 ? std::min(hi - lo, 32.0 / kappa) : hi - lo;
  const int n = std::clamp(static_cast<int>(std::ceil(kappa * len / step)), 1, kMaxBeamSubPieces);
  const double w = len / n;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double sa = lo + i * w;
    const double sb = i == n - 1 ? lo + len : sa + w;
    const std::array<double, 4> m = piece_moments(f, d, sa, sb);
    if (rule == BeamMediumRule::kMidpoint || !(m[0] > 0.0)) {
      sum += m[0] * std::exp(-kappa * (shift + 0.5 * (sa + sb) - lo));
      continue;
    }
    const DensityGauss2 g = density_gauss2(m, sa, sb);
    for (int k = 0; k < 2; ++k) sum += g.w[k] * std::exp(-kappa * (shift + g.x[k] - lo));
  }
  return sum;
}

double beam_rule_worst_error(const Density& f, double kappa, BeamMediumRule rule,
                             double step) {
  double worst = 0.0;
  unsigned lcg = 12345;
  auto next = [&lcg] {
    lcg = lcg * 1664525u + 1013904223u;
    return (lcg >> 8) / 16777216.0;
  };
  for (int row = 0; row <= 11; ++row) {  // d = 0, 0.09, ..., 0.99
    const double d = 0.09 * row;
    const double h = std::sqrt((1.0 - d) * (1.0 + d));
    const double chord = beam_piece_exact(f, d, -h, h, 0.0);
    for (int piece = 0; piece < 3; ++piece) {
      double a = -h, b = h;  // piece 0: the whole chord
      if (piece > 0) {
        a = -h + 2.0 * h * next();
        b = -h + 2.0 * h * next();
        if (a > b) std::swap(a, b);
      }
      const double exact = beam_piece_exact(f, d, a, b, kappa);
      if (!(exact > 1e-6 * chord)) continue;
      worst = std::max(worst, std::abs(beam_piece_rule(f, d, a, b, kappa, rule, step) - exact) /
                                  exact);
    }
  }
  return worst;
}

double beam_medium_exact(const Density& f, double r, double d, double sigma) {
  return chord_integral(f, r, d, [sigma](double s) { return std::cosh(sigma * s); });
}

ChordMoments chord_moments(const Density& f, double r, double d) {
  ChordMoments m;
  m.m0 = chord_integral(f, r, d, [](double) { return 1.0; });
  m.m2 = chord_integral(f, r, d, [](double s) { return s * s; });
  m.m4 = chord_integral(f, r, d, [](double s) { return s * s * s * s; });
  return m;
}

double beam_medium_series(const ChordMoments& m, double sigma, int terms) {
  const double s2 = sigma * sigma;
  double a = m.m0;
  if (terms >= 2) a += s2 * m.m2 / 2.0;
  if (terms >= 3) a += s2 * s2 * m.m4 / 24.0;
  return a;
}

}  // namespace beamcast
