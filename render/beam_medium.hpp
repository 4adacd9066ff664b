// A spherical beam seen through a homogeneous medium (issue 15, item 4;
// docs/media.md): the exact integral and the approximations, in double.
//
// Along a chord at distance d (< r) from the centre of a beam of radius r,
// with s the signed distance along the chord from its midpoint (|s| <= h,
// h = sqrt(r^2 - d^2)), the light the beam adds to the eye through a medium
// of extinction sigma is e^(-sigma s0) A, s0 the eye's distance to the
// midpoint and
//   A(sigma) = integral over the chord of f(sqrt(d^2 + s^2) / r) e^(-sigma s) ds
//            = integral of f cosh(sigma s) ds      (f is even in s)
//            = sum over n of sigma^(2n) M_2n / (2n)!,   M_k = integral of f s^k ds.
// Without the medium A = M_0, the line-integral table's value; the
// approximations differ in how many even moments they keep.
#pragma once

#include "protocol/density.hpp"

namespace beamcast {

// A(sigma) over the whole chord by adaptive Gauss-Kronrod (split at the
// density's breakpoints), relative tolerance 1e-12.
double beam_medium_exact(const Density& f, double r, double d, double sigma);

struct ChordMoments {
  double m0 = 0.0, m2 = 0.0, m4 = 0.0;  // integral of f s^k ds over the chord
};
ChordMoments chord_moments(const Density& f, double r, double d);

// The moment series cut after sigma^(2 terms - 2): terms = 1 is the chord's
// integral alone (attenuation by the midpoint's distance), 2 adds
// sigma^2 M_2 / 2, 3 adds sigma^4 M_4 / 24.
double beam_medium_series(const ChordMoments& m, double sigma, int terms);

}  // namespace beamcast
