// Radial density functions f(x) of a beam, x = distance / radius.
// f(x) = 0 for x >= 1; the renderer only ever sees f through these calls.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace beamcast {

enum class DensityKind {
  kAbe,        // paper eq 2.1: 99 for x <= 0.01, 1/x - 1 below 1
  kShell,      // paper eq 3.1: 5 - |100 (x - 0.8)| on 0.75 < x < 0.85
  kLinear,     // 1 - x
  kQuadratic,  // 1 - x^2
  kGaussian,   // exp(-x^2 / (2 sigma^2)), cut at x = 1
  kTable,      // user samples on [0, 1], uniformly spaced, linear in between
};

struct Density {
  DensityKind kind = DensityKind::kLinear;
  double sigma = 0.4;           // kGaussian only
  std::vector<double> samples;  // kTable only: samples[i] = f(i / (n - 1))

  // f(x) in double; 0 for x >= 1 and for x < 0.
  double operator()(double x) const;
  // Points in (0, 1] where f or its derivative jumps, sorted; always ends with 1.
  // Quadrature splits its intervals there.
  std::vector<double> breakpoints() const;
  // Upper bound of f on [0, 1).
  double max_value() const;
  // A string that identifies the function exactly (cache key for tables).
  std::string key() const;
  // Short human name: "abe", "shell", "gaussian(0.4)", "table(17)".
  std::string name() const;
};

// Whether the shader has the exact antiderivative of this density (the
// "closed_form" method): abe, linear, quadratic, gaussian.
bool has_closed_form(const Density& density);

// The built-in density for a name ("abe", "shell", "linear", "quadratic",
// "gaussian"); false if the name is unknown.
bool density_from_name(const std::string& name, Density* out);
// Those names, in order.
std::vector<std::string_view> density_names();

}  // namespace beamcast
