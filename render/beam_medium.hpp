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

#include <array>

#include "protocol/density.hpp"
#include "protocol/medium.hpp"

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

// ---- A piece of a chord, as the renderer integrates it ----------------------
// In units of the radius: d the chord's distance from the centre (< 1), tau
// the position along it from its midpoint, a piece [a, b] of it, and
// kappa = sigma_t r the optical depth per unit of tau. The light of the
// piece relative to the attenuation at its start:
//   I = integral over [a, b] of f(sqrt(d^2 + tau^2)) e^(-kappa (tau - a)) dtau.

// I by adaptive Gauss-Kronrod (split at the density's breakpoints).
double beam_piece_exact(const Density& f, double d, double a, double b, double kappa);

// The integrals of f tau^n over [a, b], n = 0..3: what the renderer's moment
// table (LineIntegralTable::gm) differences give.
std::array<double, 4> piece_moments(const Density& f, double d, double a, double b);

// One sub-piece [a, b] by the two-node Gauss rule whose weight is f, from its
// moments m (piece_moments): nodes x (in tau) and weights w (summing to
// m[0]), as shaders/beam_math.glsl forms them (mean, variance and third
// central moment clamped to what a distribution on [a, b] can have; one node
// at the mean where the variance is below 1e-6 (b - a)^2).
struct DensityGauss2 {
  double x[2] = {0.0, 0.0};
  double w[2] = {0.0, 0.0};
};
DensityGauss2 density_gauss2(const std::array<double, 4>& m, double a, double b);

// I by the renderer's rule (shaders/beam_math.glsl, medium_piece) in double
// with exact moments: [a, b] split into ceil(kappa (b - a) / step) equal
// sub-pieces (over at most the first 32 of optical depth; at most
// kMaxBeamSubPieces), each by density_gauss2 (kGauss2) or by its integral
// of f attenuated at its midpoint (kMidpoint).
double beam_piece_rule(const Density& f, double d, double a, double b, double kappa,
                       BeamMediumRule rule, double step);

// The worst relative error of beam_piece_rule against beam_piece_exact over
// whole chords (d from 0 to 0.99 in steps of 0.09) and two pieces of each
// (ends from a fixed pseudo-random sequence), skipping pieces that hold
// under 1e-6 of their chord's light (their relative error says nothing).
// What tests/unit/test_beam_medium.cpp bounds and `beamcast bench
// medium-rule` prints for docs/media.md.
double beam_rule_worst_error(const Density& f, double kappa, BeamMediumRule rule, double step);

}  // namespace beamcast
