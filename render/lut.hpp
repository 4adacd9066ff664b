// Line-integral tables of a density, built on the CPU in double precision.
//
//   g(d, s) = integral_0^s f( sqrt(d^2 + (t - 1)^2) ) dt,  d in [0, 1], s in [0, 2]
//
// (the paper's eq 2.2, in units of the radius). The GPU samples these tables;
// the CPU never samples one to make a pixel (the CPU reference integrates f).
#pragma once

#include <vector>

#include "protocol/density.hpp"

namespace beamcast {

struct LineIntegralTable {
  int nd = 0;  // rows: d_i = i / (nd - 1)
  int ns = 0;  // columns: s_j = 2 j / (ns - 1)
  std::vector<float> g;  // g[i * ns + j] = g(d_i, s_j)
  int nf = 0;  // 1D table of f: f_k = f(k / (nf - 1)), for the near-parallel path
  std::vector<float> f;
};

// g(d, s) in double, splitting the integral at every point where f has a kink or
// jump (density breakpoints mapped to t) and integrating each piece with
// adaptive Gauss-Kronrod to relative tolerance ~1e-12.
double line_integral(const Density& density, double d, double s);

// The whole table; each row is built cumulatively along s.
LineIntegralTable build_table(const Density& density, int nd, int ns, int nf);

}  // namespace beamcast
