#include "protocol/density.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace beamcast {

double Density::operator()(double x) const {
  if (!(x >= 0.0) || x >= 1.0) return 0.0;
  switch (kind) {
    case DensityKind::kAbe:
      return x <= 0.01 ? 99.0 : 1.0 / x - 1.0;
    case DensityKind::kShell:
      return (x > 0.75 && x < 0.85) ? 5.0 - std::abs(100.0 * (x - 0.8)) : 0.0;
    case DensityKind::kLinear:
      return 1.0 - x;
    case DensityKind::kQuadratic:
      return 1.0 - x * x;
    case DensityKind::kGaussian:
      return std::exp(-x * x / (2.0 * sigma * sigma));
    case DensityKind::kTable: {
      const double u = x * static_cast<double>(samples.size() - 1);
      const auto i = std::min(static_cast<std::size_t>(u), samples.size() - 2);
      const double a = u - static_cast<double>(i);
      return samples[i] * (1.0 - a) + samples[i + 1] * a;
    }
  }
  return 0.0;
}

std::vector<double> Density::breakpoints() const {
  switch (kind) {
    case DensityKind::kAbe:
      return {0.01, 1.0};
    case DensityKind::kShell:
      return {0.75, 0.8, 0.85, 1.0};
    case DensityKind::kTable: {
      std::vector<double> b;
      const std::size_t n = samples.size();
      for (std::size_t i = 1; i < n; ++i) b.push_back(static_cast<double>(i) / (n - 1));
      return b;
    }
    default:
      return {1.0};
  }
}

double Density::max_value() const {
  switch (kind) {
    case DensityKind::kAbe:
      return 99.0;
    case DensityKind::kShell:
      return 5.0;
    case DensityKind::kTable:
      return samples.empty() ? 0.0 : *std::max_element(samples.begin(), samples.end());
    default:
      return 1.0;
  }
}

std::string Density::name() const {
  char buf[64];
  switch (kind) {
    case DensityKind::kAbe:
      return "abe";
    case DensityKind::kShell:
      return "shell";
    case DensityKind::kLinear:
      return "linear";
    case DensityKind::kQuadratic:
      return "quadratic";
    case DensityKind::kGaussian:
      std::snprintf(buf, sizeof buf, "gaussian(%g)", sigma);
      return buf;
    case DensityKind::kTable:
      std::snprintf(buf, sizeof buf, "table(%zu)", samples.size());
      return buf;
  }
  return "?";
}

std::string Density::key() const {
  std::string k = name();
  if (kind == DensityKind::kGaussian || kind == DensityKind::kTable) {
    // Exact bit patterns so two densities share a table only if identical.
    auto append_bits = [&k](double v) {
      char buf[24];
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      std::snprintf(buf, sizeof buf, ":%016llx", static_cast<unsigned long long>(bits));
      k += buf;
    };
    if (kind == DensityKind::kGaussian) append_bits(sigma);
    for (double s : samples) append_bits(s);
  }
  return k;
}

bool has_closed_form(const Density& density) {
  return density.kind == DensityKind::kAbe || density.kind == DensityKind::kLinear ||
         density.kind == DensityKind::kQuadratic || density.kind == DensityKind::kGaussian;
}

namespace {
const struct {
  const char* name;
  DensityKind kind;
} kBuiltins[] = {{"abe", DensityKind::kAbe},
                 {"shell", DensityKind::kShell},
                 {"linear", DensityKind::kLinear},
                 {"quadratic", DensityKind::kQuadratic},
                 {"gaussian", DensityKind::kGaussian}};
}  // namespace

std::vector<std::string_view> density_names() {
  std::vector<std::string_view> names;
  for (const auto& b : kBuiltins) names.emplace_back(b.name);
  return names;
}

bool density_from_name(const std::string& name, Density* out) {
  for (const auto& b : kBuiltins) {
    if (name == b.name) {
      *out = Density{};
      out->kind = b.kind;
      return true;
    }
  }
  return false;
}

}  // namespace beamcast
