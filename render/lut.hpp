// Line-integral tables of a density, built on the CPU in double precision.
//
//   g(d, s) = integral_0^s f( sqrt(d^2 + (t - 1)^2) ) dt,  d in [0, 1], s in [0, 2]
//
// (the paper's eq 2.2, in units of the radius). The GPU samples these tables;
// the CPU never samples one to make a pixel (the CPU reference integrates f).
#pragma once

#include <vector>

#include "protocol/density.hpp"
#include "protocol/scene.hpp"

namespace beamcast {

// Layouts (docs/accuracy.md measures them):
//  rows    uniform: d_i = i / (nd - 1)
//          warped:  d_i = W^-1(i / (nd - 1)), W the density's warp below
//  columns uniform: s_j = 2 j / (ns - 1)
//          chord:   s_ij = 1 + (2 j / (ns - 1) - 1) sqrt(1 - d_i^2), so every column
//                   lies inside the unit disk and none is spent where g is constant
struct LineIntegralTable {
  TableLayout layout = TableLayout::kUniform;
  int nd = 0;
  int ns = 0;
  std::vector<float> g;  // g[i * ns + j] = g(d_i, s_ij)
  // Warped layouts: W(d) at d_m = m / (nw - 1), increasing from 0 to 1. The
  // shader finds the row coordinate of d as W(d) (nd - 1). Row density follows
  // sqrt(max_s |d^2 g / dd^2|), which spreads linear interpolation error
  // (h^2 |g''| / 8) evenly over d, plus a floor so no region starves.
  int nw = 0;
  std::vector<float> warp;
  int nf = 0;  // 1D table of f: f_k = f(k / (nf - 1)), for the near-parallel path
  std::vector<float> f;
  // Only for scenes with a medium (build_table's `moments`): at each texel
  // (g, G1, G2, G3), G_n(d, s) = integral_0^s f(...) (t - 1)^n dt, the
  // moments about the chord's midpoint (a beam seen through a medium,
  // docs/media.md); 4 floats per texel, rows as g.
  std::vector<float> gm;
};

// g(d, s) in double, splitting the integral at every point where f has a kink or
// jump (density breakpoints mapped to t) and integrating each piece with
// adaptive Gauss-Kronrod to relative tolerance ~1e-12.
double line_integral(const Density& density, double d, double s);

// The whole table; each row is built cumulatively along s.
LineIntegralTable build_table(const Density& density, int nd, int ns, int nf,
                              TableLayout layout = TableLayout::kUniform, bool moments = false);

// Row positions of a table with `nd` rows and the given layout (d_i above).
std::vector<double> table_rows(const LineIntegralTable& table);

}  // namespace beamcast
