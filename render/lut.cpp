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

  // Integral of f (t - 1)^power over [a, b] (a <= b), split at the breakpoints inside.
  double integrate(double a, double b, int power = 0) const {
    if (empty) return 0.0;
    const double lo = std::max(a, t.front());
    const double hi = std::min(b, t.back());
    if (!(hi > lo)) return 0.0;
    double pts[64];
    std::vector<double> big;
    double* p = pts;
    if (t.size() + 2 > std::size(pts)) {
      big.resize(t.size() + 2);
      p = big.data();
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
    return quad::integrate_pieces(
               [&self, power](double x) {
                 const double v = self(x);
                 double w = 1.0;
                 for (int k = 0; k < power; ++k) w *= x - 1.0;
                 return v * w;
               },
               p, n, opt)
        .value;
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

namespace {

bool chord_columns(TableLayout l) {
  return l == TableLayout::kChord || l == TableLayout::kChordWarped;
}
bool warped_rows(TableLayout l) {
  return l == TableLayout::kWarped || l == TableLayout::kChordWarped;
}

// Column positions of row d: uniform on [0, 2] or uniform across the chord.
void row_columns(double d, int ns, bool chord, std::vector<double>* s) {
  s->resize(static_cast<std::size_t>(ns));
  const double c = d < 1.0 ? std::sqrt((1.0 - d) * (1.0 + d)) : 0.0;
  for (int j = 0; j < ns; ++j) {
    const double u = static_cast<double>(j) / (ns - 1);
    (*s)[j] = chord ? 1.0 + (2.0 * u - 1.0) * c : 2.0 * u;
  }
}

// g along one row at the given increasing columns, cumulatively.
void integrate_row(const Density& density, double d, const std::vector<double>& s, float* out) {
  const Row row(density, d);
  double acc = row.integrate(0.0, s[0]);
  out[0] = static_cast<float>(acc);
  for (std::size_t j = 1; j < s.size(); ++j) {
    acc += row.integrate(s[j - 1], s[j]);
    out[j] = static_cast<float>(acc);
  }
}

// G_1..G_3 along one row (moments about the chord's midpoint), cumulatively,
// into out[4 j + n]; out[4 j] gets g.
void integrate_row_moments(const Density& density, double d, const std::vector<double>& s,
                           const float* g, float* out) {
  const Row row(density, d);
  double acc[4] = {0.0, 0.0, 0.0, 0.0};
  for (std::size_t j = 0; j < s.size(); ++j) {
    const double a = j == 0 ? 0.0 : s[j - 1];
    out[4 * j] = g[j];
    for (int n = 1; n < 4; ++n) {
      acc[n] += row.integrate(a, s[j], n);
      out[4 * j + n] = static_cast<float>(acc[n]);
    }
  }
}

// Runs body(i) for i in [0, n) on all cores, rows interleaved (rows with small d
// cost more, so interleaving balances the load).
template <typename Body>
void parallel_rows(int n, long long work, const Body& body) {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const int nthreads = static_cast<int>(std::min<unsigned>(hw, static_cast<unsigned>(n)));
  if (nthreads <= 1 || work < 4096) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(nthreads);
  for (int k = 0; k < nthreads; ++k) {
    pool.emplace_back([&, k] {
      for (int i = k; i < n; i += nthreads) body(i);
    });
  }
  for (auto& th : pool) th.join();
}

// The warp W(d) on nw uniform points (see lut.hpp): from a fine uniform-d table
// in the same column layout, the second difference across rows, maximized over
// columns; row density ~ sqrt of it, smoothed, plus 10% of its mean as a floor.
std::vector<double> compute_warp(const Density& density, int nw, bool chord) {
  const int kColumns = 257;
  std::vector<float> fine(static_cast<std::size_t>(nw) * kColumns);
  parallel_rows(nw, static_cast<long long>(nw) * kColumns, [&](int m) {
    std::vector<double> s;
    const double d = static_cast<double>(m) / (nw - 1);
    row_columns(d, kColumns, chord, &s);
    integrate_row(density, d, s, &fine[static_cast<std::size_t>(m) * kColumns]);
  });
  std::vector<double> rho(static_cast<std::size_t>(nw), 0.0);
  for (int m = 1; m + 1 < nw; ++m) {
    double worst = 0.0;
    for (int k = 0; k < kColumns; ++k) {
      const auto at = [&](int mm) { return static_cast<double>(fine[mm * kColumns + k]); };
      worst = std::max(worst, std::abs(at(m + 1) - 2.0 * at(m) + at(m - 1)));
    }
    rho[m] = std::sqrt(worst);
  }
  rho[0] = rho[1];
  rho[nw - 1] = rho[nw - 2];
  std::vector<double> smooth(rho.size());
  for (int m = 0; m < nw; ++m) {
    double sum = 0.0;
    int count = 0;
    for (int k = std::max(0, m - 3); k <= std::min(nw - 1, m + 3); ++k, ++count) sum += rho[k];
    smooth[m] = sum / count;
  }
  double mean = 0.0;
  for (double r : smooth) mean += r;
  mean /= nw;
  if (!(mean > 0.0)) mean = 1.0;  // g linear in d everywhere: uniform rows
  std::vector<double> w(static_cast<std::size_t>(nw), 0.0);
  for (int m = 1; m < nw; ++m) {
    w[m] = w[m - 1] + 0.5 * (smooth[m - 1] + smooth[m]) + 0.1 * mean;
  }
  for (double& x : w) x /= w.back();
  return w;
}

// d with W(d) = u for the piecewise-linear W on uniform points.
double invert_warp(const std::vector<double>& w, double u) {
  const int nw = static_cast<int>(w.size());
  const auto it = std::upper_bound(w.begin(), w.end(), u);
  if (it == w.begin()) return 0.0;
  if (it == w.end()) return 1.0;
  const int m = static_cast<int>(it - w.begin()) - 1;
  const double a = (u - w[m]) / (w[m + 1] - w[m]);
  return (m + a) / (nw - 1);
}

}  // namespace

std::vector<double> table_rows(const LineIntegralTable& table) {
  std::vector<double> rows(static_cast<std::size_t>(table.nd));
  std::vector<double> w(table.warp.begin(), table.warp.end());
  for (int i = 0; i < table.nd; ++i) {
    const double u = static_cast<double>(i) / (table.nd - 1);
    rows[i] = w.empty() ? u : invert_warp(w, u);
  }
  return rows;
}

LineIntegralTable build_table(const Density& density, int nd, int ns, int nf,
                              TableLayout layout, bool moments) {
  check_size("nd", nd);
  check_size("ns", ns);
  check_size("nf", nf);
  LineIntegralTable table;
  table.layout = layout;
  table.nd = nd;
  table.ns = ns;
  table.nf = nf;
  table.g.assign(static_cast<std::size_t>(nd) * ns, 0.0f);
  table.f.resize(static_cast<std::size_t>(nf));
  const bool chord = chord_columns(layout);
  std::vector<double> w;
  if (warped_rows(layout)) {
    table.nw = 1024;
    w = compute_warp(density, table.nw, chord);
    table.warp.assign(w.begin(), w.end());
  }
  // Rows from the double-precision warp, not its float copy.
  std::vector<double> rows(static_cast<std::size_t>(nd));
  for (int i = 0; i < nd; ++i) {
    const double u = static_cast<double>(i) / (nd - 1);
    rows[i] = w.empty() ? u : invert_warp(w, u);
  }
  parallel_rows(nd, static_cast<long long>(nd) * ns, [&](int i) {
    std::vector<double> s;
    row_columns(rows[i], ns, chord, &s);
    integrate_row(density, rows[i], s, &table.g[static_cast<std::size_t>(i) * ns]);
  });
  if (moments) {
    table.gm.assign(static_cast<std::size_t>(nd) * ns * 4, 0.0f);
    parallel_rows(nd, static_cast<long long>(nd) * ns, [&](int i) {
      std::vector<double> s;
      row_columns(rows[i], ns, chord, &s);
      const std::size_t row0 = static_cast<std::size_t>(i) * ns;
      integrate_row_moments(density, rows[i], s, &table.g[row0], &table.gm[4 * row0]);
    });
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
