#include "render/beam_medium.hpp"

#include <cmath>
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

}  // namespace

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
