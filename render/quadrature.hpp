// Adaptive Gauss-Kronrod quadrature (G7-K15), header-only, templated on the
// integrand. Used by the line-integral tables (lut.cpp) and the CPU reference
// renderer (reference.cpp); both split their integrals at every kink or jump of
// the integrand first, so each piece handed in here is smooth.
//
// The scheme is QUADPACK's QAG with a shared pool: every input piece starts as
// one interval, and the interval with the largest error estimate is bisected
// until the summed estimate meets max(abs_tol, rel_tol * |integral|). A smooth
// piece therefore costs exactly one 15-point rule.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace beamcast::quad {

// One application of the 15-point Kronrod rule with the embedded 7-point
// Gauss rule on [a, b].
struct Gk15Result {
  double value = 0.0;  // Kronrod estimate
  double error = 0.0;  // QUADPACK's error estimate
};

template <class F>
inline Gk15Result gk15(F& f, double a, double b) {
  // Nodes and weights from QUADPACK (qk15).
  static constexpr double xgk[8] = {
      0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
      0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
      0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
      0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
  static constexpr double wgk[8] = {
      0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
      0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
      0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
      0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  static constexpr double wg[4] = {
      0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
      0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

  const double center = 0.5 * (a + b);
  const double half = 0.5 * (b - a);
  const double fc = f(center);
  double resk = fc * wgk[7];
  double resg = fc * wg[3];
  double resabs = std::abs(resk);
  double fv1[7];
  double fv2[7];
  for (int j = 0; j < 7; ++j) {
    const double dx = half * xgk[j];
    const double f1 = f(center - dx);
    const double f2 = f(center + dx);
    fv1[j] = f1;
    fv2[j] = f2;
    resk += wgk[j] * (f1 + f2);
    resabs += wgk[j] * (std::abs(f1) + std::abs(f2));
    if (j % 2 == 1) resg += wg[j / 2] * (f1 + f2);
  }
  const double mean = 0.5 * resk;
  double resasc = wgk[7] * std::abs(fc - mean);
  for (int j = 0; j < 7; ++j) resasc += wgk[j] * (std::abs(fv1[j] - mean) + std::abs(fv2[j] - mean));

  const double ah = std::abs(half);
  Gk15Result r;
  r.value = resk * half;
  resabs *= ah;
  resasc *= ah;
  double err = std::abs((resk - resg) * half);
  if (resasc != 0.0 && err != 0.0) err = resasc * std::min(1.0, std::pow(200.0 * err / resasc, 1.5));
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  constexpr double kUflow = std::numeric_limits<double>::min();
  if (resabs > kUflow / (50.0 * kEps)) err = std::max(50.0 * kEps * resabs, err);
  r.error = err;
  return r;
}

struct Options {
  double rel_tol = 1e-12;
  double abs_tol = 0.0;       // absolute floor of the requested accuracy
  int max_intervals = 4000;   // stop refining (and return the best value) beyond this
};

struct Result {
  double value = 0.0;
  double error = 0.0;  // summed error estimate
  int intervals = 0;   // final number of intervals
  bool converged = true;
};

namespace detail {
struct Interval {
  double a, b, value, error;
  bool operator<(const Interval& o) const { return error < o.error; }  // max-heap on error
};
}  // namespace detail

// Integrates f over the union of [pts[i], pts[i+1]] for i = 0 .. n-2; pts must be
// non-decreasing (empty pieces are skipped). Each piece should be smooth.
template <class F>
Result integrate_pieces(F&& f, const double* pts, std::size_t n, const Options& opt = {}) {
  Result res;
  if (n < 2) return res;
  std::vector<detail::Interval> heap;  // local: the integrand may itself integrate
  heap.reserve(std::max<std::size_t>(32, 2 * n));
  double total = 0.0;
  double total_err = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double a = pts[i];
    const double b = pts[i + 1];
    if (!(b > a)) continue;
    const Gk15Result g = gk15(f, a, b);
    heap.push_back({a, b, g.value, g.error});
    total += g.value;
    total_err += g.error;
  }
  std::make_heap(heap.begin(), heap.end());
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  int guard = 0;
  while (!heap.empty()) {
    const double tol = std::max(opt.abs_tol, opt.rel_tol * std::abs(total));
    if (total_err <= tol) break;
    if (static_cast<int>(heap.size()) >= opt.max_intervals) {
      res.converged = false;
      break;
    }
    std::pop_heap(heap.begin(), heap.end());
    const detail::Interval worst = heap.back();
    heap.pop_back();
    if (worst.error <= 0.0) {  // everything left is exact (or too small to split)
      heap.push_back(worst);
      break;
    }
    const double mid = 0.5 * (worst.a + worst.b);
    const double scale = std::max(std::abs(worst.a), std::abs(worst.b));
    if (!(mid > worst.a && mid < worst.b) || worst.b - worst.a <= 64.0 * kEps * scale) {
      // Cannot usefully split further: accept this interval as it is.
      total_err -= worst.error;
      res.converged = false;
      heap.push_back({worst.a, worst.b, worst.value, 0.0});
      std::push_heap(heap.begin(), heap.end());
      continue;
    }
    const Gk15Result l = gk15(f, worst.a, mid);
    const Gk15Result r = gk15(f, mid, worst.b);
    total += l.value + r.value - worst.value;
    total_err += l.error + r.error - worst.error;
    heap.push_back({worst.a, mid, l.value, l.error});
    std::push_heap(heap.begin(), heap.end());
    heap.push_back({mid, worst.b, r.value, r.error});
    std::push_heap(heap.begin(), heap.end());
    // Running sums drift; recompute them now and then.
    if (++guard % 64 == 0) {
      total = 0.0;
      total_err = 0.0;
      for (const auto& iv : heap) {
        total += iv.value;
        total_err += iv.error;
      }
    }
  }
  // Final sums from scratch (no drift in the returned value).
  res.value = 0.0;
  res.error = 0.0;
  for (const auto& iv : heap) {
    res.value += iv.value;
    res.error += iv.error;
  }
  res.intervals = static_cast<int>(heap.size());
  return res;
}

template <class F>
Result integrate(F&& f, double a, double b, const Options& opt = {}) {
  if (b < a) {
    Result r = integrate(f, b, a, opt);
    r.value = -r.value;
    return r;
  }
  const double pts[2] = {a, b};
  return integrate_pieces(f, pts, 2, opt);
}

}  // namespace beamcast::quad
