// Schlick's phase function for participating media (issue 15, item 5; seed
// 001 §5, digest §2), in double.
//
// Convention: mu is the cosine of the scattering angle, between the
// direction the light travelled in before the event and the direction it
// leaves in (mu = 1: straight on, mu = -1: straight back). Then
//   p(mu) = (1 - k^2) / (4 pi (1 - k mu)^2),   |k| < 1,
// normalized over the sphere (2 pi times the integral over mu is 1); k > 0
// scatters forward, like a Henyey-Greenstein lobe with g ~ k for small k
// (k = 1.55 g - 0.55 g^3 matches the two, Blasi, Le Saec and Schlick 1993).
//
// The sign: the seed writes p = (1 - k^2) / (4 pi (1 + k cos theta)^2), with
// theta measured from the direction back towards where the light came from
// (cos theta = -mu), and samples cos = (2 xi + k - 1) / (2 k xi - k + 1),
// which is the inverse distribution of the (1 - k cos)^-2 form, i.e. with
// theta measured from the travel direction. Taken together as printed, the
// two disagree in the sign of k (a lobe sampled forward, evaluated as
// backward). Here both use mu as above.
#pragma once

#include "protocol/medium.hpp"
#include "protocol/vec.hpp"

namespace beamcast {

// kSchlickMaxG and schlick_k_from_g (from Henyey-Greenstein g) live with the
// scene's medium, protocol/medium.hpp.

// p(mu) per steradian.
double schlick_phase(double k, double mu);

// The mu whose cumulative probability is xi in [0, 1] (inverse transform):
//   mu = (2 xi + k - 1) / (2 k xi - k + 1).
double schlick_sample_mu(double k, double xi);

// Its cumulative distribution P(mu' <= mu) = 2 pi * integral of p over [-1, mu].
double schlick_cdf(double k, double mu);

// A direction scattered from `travel` (unit): mu from xi1, the azimuth
// 2 pi xi2 about `travel`.
Vec3 schlick_sample_direction(double k, const Vec3& travel, double xi1, double xi2);

}  // namespace beamcast
