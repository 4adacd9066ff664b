#include "render/lut.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "render/quadrature.hpp"

namespace beamcast {
namespace {

// Everything about one row (one value of d) of the line integral: the integrand
// and the sorted t at which it has a kink or jump, including the ends of the
// chord [1 - c, 1 + c] of the unit circle outside which it is zero.
struct Row {
  const Density* density = nullptr;
  double d = 0.0;
  double fmax = 1.0;
  bool empty = true;      // d >= 1: the line misses the unit disk
  std::vector<double> t;  // breakpoints, sorted; front/back are the chord ends

  Row(const Density& dens, double dd) : density(&dens), d(std::abs(dd)) {
    fmax = std::max(1.0, std::abs(dens.max_value()));
    if (!(d < 1.0)) return;
    empty = false;
    const double c = std::sqrt((1.0 - d) * (1.0 + d));
    t.push_back(1.0 - c);
    t.push_back(1.0);  // closest approach: the distance has a kink-like minimum there
    t.push_back(1.0 + c);
    // Graded points at 1 +- d 4^k: for d << 1 the distance sqrt(d^2 + tau^2)
    // bends on the scale d near tau = 0, a feature a 15-point rule on the whole
    // chord can miss without noticing (its error estimate sees only |tau|).
    // Scale-similar pieces [d 4^k, d 4^(k+1)] are each integrated to ~1e-15.
    // Below d = 1e-8 the bend changes the integral by < d^2 ln(1/d) ~ 1e-15.
    for (double g = std::max(d, 1e-8); d > 0.0 && g < 0.25 * c; g *= 4.0) {
      t.push_back(1.0 - g);
      t.push_back(1.0 + g);
    }
    for (double x : dens.breakpoints()) {
      if (x > d && x < 1.0) {
        // sqrt(x^2 - d^2) in factored form (no cancellation for x close to d).
        const double h = std::sqrt((x - d) * (x + d));
        t.push_back(1.0 - h);
        t.push_back(1.0 + h);
      }
    }
    std::sort(t.begin(), t.end());
  }

  double operator()(double tt) const {
    const double tau = tt - 1.0;
    return (*density)(std::sqrt(d * d + tau * tau));
  }

  // Integral over [a, b] (a <= b), split at the breakpoints inside.
  double integrate(double a, double b) const {
    if (empty) return 0.0;
    const double lo = std::max(a, t.front());
    const double hi = std::min(b, t.back());
    if (!(hi > lo)) return 0.0;
    double pts[64];
    std::vector<double> big;
    double* p = pts;
    std::size_t cap = 64;
    if (t.size() + 2 > cap) {
      big.resize(t.size() + 2);
      p = big.data();
      cap = big.size();
    }
    std::size_t n = 0;
    p[n++] = lo;
    for (double x : t) {
      if (x > lo && x < hi) p[n++] = x;
    }
    p[n++] = hi;
    quad::Options opt;
    opt.rel_tol = 1e-12;
    // Absolute floor: far below anything a float table or a pixel can show.
    opt.abs_tol = 1e-15 * fmax * (hi - lo);
    const auto& self = *this;
    return quad::integrate_pieces([&self](double x) { return self(x); }, p, n, opt).value;
  }
};

void check_size(const char* what, int n) {
  if (n < 2 || n > 4096) {
    throw std::invalid_argument(std::string("build_table: ") + what + " = " + std::to_string(n) +
                                " is outside 2..4096");
  }
}

}  // namespace

double line_integral(const Density& density, double d, double s) {
  const Row row(density, d);
  if (s >= 0.0) return row.integrate(0.0, s);
  return -row.integrate(s, 0.0);
}

LineIntegralTable build_table(const Density& density, int nd, int ns, int nf) {
  check_size("nd", nd);
  check_size("ns", ns);
  check_size("nf", nf);
  LineIntegralTable table;
  table.nd = nd;
  table.ns = ns;
  table.nf = nf;
  table.g.assign(static_cast<std::size_t>(nd) * ns, 0.0f);
  table.f.resize(static_cast<std::size_t>(nf));

  std::vector<double> s(static_cast<std::size_t>(ns));
  for (int j = 0; j < ns; ++j) s[j] = 2.0 * j / (ns - 1);

  auto build_row = [&](int i) {
    const Row row(density, static_cast<double>(i) / (nd - 1));
    float* out = &table.g[static_cast<std::size_t>(i) * ns];
    out[0] = 0.0f;
    double acc = 0.0;
    for (int j = 1; j < ns; ++j) {
      acc += row.integrate(s[j - 1], s[j]);
      out[j] = static_cast<float>(acc);
    }
  };

  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int nthreads = static_cast<int>(std::min<unsigned>(hw, static_cast<unsigned>(nd)));
  if (nthreads <= 1 || static_cast<long long>(nd) * ns < 4096) {
    for (int i = 0; i < nd; ++i) build_row(i);
  } else {
    std::vector<std::thread> pool;
    pool.reserve(nthreads);
    for (int k = 0; k < nthreads; ++k) {
      // Interleaved rows: rows with small d cost more, so this balances the load.
      pool.emplace_back([&, k] {
        for (int i = k; i < nd; i += nthreads) build_row(i);
      });
    }
    for (auto& th : pool) th.join();
  }

  for (int k = 0; k < nf; ++k) {
    // Left limit at x = 1, where f jumps to 0 (e.g. the cut gaussian), so that
    // linear interpolation of the table does not smear the jump inward.
    const double x = std::min(static_cast<double>(k) / (nf - 1), 1.0 - 1e-12);
    table.f[k] = static_cast<float>(density(x));
  }
  return table;
}

}  // namespace beamcast
