// The volume model's functions (protocol/volume.hpp): transfer functions,
// placement, trilinear sampling, the analytic fields of the procedural
// sources and the R_v pyramid. The scene format's parsing is in
// volume_json.cpp, the file readers in volume_files.cpp.
#include "protocol/volume.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "protocol/check.hpp"

namespace beamcast {

namespace {

// Index of the last point at or below v (points sorted, v inside them).
std::size_t segment(const std::vector<TransferPoint>& p, double v) {
  const auto it = std::upper_bound(p.begin(), p.end(), v,
                                   [](double x, const TransferPoint& q) { return x < q.value; });
  return static_cast<std::size_t>(it - p.begin()) - 1;
}

// Piecewise linear in the points' values, clamped to the end points.
template <class F>
auto interpolate(const std::vector<TransferPoint>& p, double v, F&& get) {
  if (v <= p.front().value) return get(p.front());
  if (v >= p.back().value) return get(p.back());
  const std::size_t k = segment(p, v);
  const double t = (v - p[k].value) / (p[k + 1].value - p[k].value);
  return (1.0 - t) * get(p[k]) + t * get(p[k + 1]);
}

std::array<double, 4> conjugate(const std::array<double, 4>& q) {
  return {q[0], -q[1], -q[2], -q[3]};
}

// The procedural field's coordinate on [-1, 1] of grid coordinate g on an
// axis of n voxels (the same expression for the grid and for exact()).
double field_coordinate(double g, int n) { return -1.0 + 2.0 * g / (n - 1); }

double procedural_value(VolumeSourceType type, double x, double y, double z) {
  return type == VolumeSourceType::kHeat ? heat_field(x, y, z) : marschner_lobb(x, y, z);
}

double normalized(double v, const std::array<double, 2>& range) {
  return std::clamp((v - range[0]) / (range[1] - range[0]), 0.0, 1.0);
}

std::uint16_t quantize(double t) { return static_cast<std::uint16_t>(std::lround(t * 65535.0)); }

bool procedural(VolumeSourceType t) {
  return t == VolumeSourceType::kMarschnerLobb || t == VolumeSourceType::kHeat;
}

}  // namespace

Color TransferFunction::color(double v) const {
  if (points.empty()) return {0.0, 0.0, 0.0};
  return interpolate(points, v, [](const TransferPoint& p) { return p.color; });
}

double TransferFunction::opacity(double v) const {
  if (points.empty()) return 0.0;
  return interpolate(points, v, [](const TransferPoint& p) { return p.opacity; });
}

Vec3 Volume::to_grid(const Vec3& world) const {
  const Vec3 local = rotate(conjugate(rotation), world - origin);
  return {local[0] / spacing[0], local[1] / spacing[1], local[2] / spacing[2]};
}

Vec3 Volume::to_world(const Vec3& g) const { return origin + rotate(rotation, mul(g, spacing)); }

void Volume::world_bounds(Vec3* lo, Vec3* hi) const {
  BEAMCAST_CHECK(grid, "a volume without a grid");
  Aabb box;
  for (int c = 0; c < 8; ++c) {
    Vec3 g;
    for (int a = 0; a < 3; ++a) g[a] = ((c >> a) & 1) ? grid->dims[a] - 1 : 0.0;
    box.grow(to_world(g));
  }
  *lo = box.lo;
  *hi = box.hi;
}

double Volume::sample(const Vec3& g) const {
  BEAMCAST_CHECK(grid, "a volume without a grid");
  const VolumeGrid& v = *grid;
  // Lower corner of the cell and the weights; the last cell of an axis takes
  // its upper face (t = 1), so clamping to n - 1 gives the face's value.
  std::array<int, 3> i0;
  Vec3 t;
  for (int a = 0; a < 3; ++a) {
    const double c = std::clamp(g[a], 0.0, v.dims[a] - 1.0);
    i0[a] = std::min(static_cast<int>(c), v.dims[a] - 2);
    t[a] = c - i0[a];
  }
  double r = 0.0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? t[0] : 1.0 - t[0]) * (dy ? t[1] : 1.0 - t[1]) * (dz ? t[2] : 1.0 - t[2]);
    if (w != 0.0) r += w * v.value(i0[0] + dx, i0[1] + dy, i0[2] + dz);
  }
  return r;
}

double Volume::exact(const Vec3& g) const {
  if (!procedural(source)) return sample(g);
  BEAMCAST_CHECK(grid, "a volume without a grid");
  Vec3 p;
  for (int a = 0; a < 3; ++a) {
    p[a] = field_coordinate(std::clamp(g[a], 0.0, grid->dims[a] - 1.0), grid->dims[a]);
  }
  return normalized(procedural_value(source, p[0], p[1], p[2]), range);
}

namespace {

// Both fields split into per-axis (or per-plane) factors, so a grid costs
// O(n^2) transcendental calls instead of O(n^3); the point functions below
// combine the same factors in the same order, so they give the grid's
// values bit for bit.
constexpr double kMlAlpha = 0.25, kMlFm = 6.0, kPi = std::numbers::pi;
double ml_z(double z) { return 1.0 - std::sin(kPi * z / 2.0); }
double ml_xy(double x, double y) {
  const double r = std::sqrt(x * x + y * y);
  return kMlAlpha * (1.0 + std::cos(2.0 * kPi * kMlFm * std::cos(kPi * r / 2.0)));
}
double ml_combine(double z_term, double xy_term) {
  return (z_term + xy_term) / (2.0 * (1.0 + kMlAlpha));
}

// Heat sources placed off-centre and off the axes, of different ages
// (s = 4 D t), so the field has no symmetry a renderer's bug could hide behind.
struct HeatSource {
  Vec3 c;
  double s, w;
};
constexpr HeatSource kHeatSources[] = {{{-0.45, -0.35, -0.3}, 0.5, 0.65},
                                       {{0.5, 0.3, 0.25}, 0.7, 0.55},
                                       {{0.1, 0.55, -0.55}, 0.35, 0.45},
                                       {{-0.2, -0.1, 0.7}, 0.9, 0.3}};
constexpr std::size_t kHeatCount = std::size(kHeatSources);
constexpr double kHeatFloor = 0.05;
// exp(-|p - c|^2 / s) = e_x e_y e_z, one factor per axis.
double heat_factor(const HeatSource& h, int axis, double x) {
  const double d = x - h.c[static_cast<std::size_t>(axis)];
  return std::exp(-d * d / h.s);
}
double heat_combine(const std::array<double, kHeatCount>& ex,
                    const std::array<double, kHeatCount>& ey,
                    const std::array<double, kHeatCount>& ez) {
  double h = kHeatFloor;
  for (std::size_t s = 0; s < kHeatCount; ++s) h += kHeatSources[s].w * (ex[s] * ey[s] * ez[s]);
  return h;
}
std::array<double, kHeatCount> heat_factors(int axis, double x) {
  std::array<double, kHeatCount> f;
  for (std::size_t s = 0; s < kHeatCount; ++s) f[s] = heat_factor(kHeatSources[s], axis, x);
  return f;
}

}  // namespace

double marschner_lobb(double x, double y, double z) { return ml_combine(ml_z(z), ml_xy(x, y)); }

double heat_field(double x, double y, double z) {
  return heat_combine(heat_factors(0, x), heat_factors(1, y), heat_factors(2, z));
}

std::shared_ptr<const VolumeGrid> procedural_grid(VolumeSourceType type, int n,
                                                  std::array<double, 2> range) {
  BEAMCAST_CHECK(procedural(type) && n >= 2, "procedural_grid of a file source or n < 2");
  auto g = std::make_shared<VolumeGrid>();
  g->dims = {n, n, n};
  g->values.resize(static_cast<std::size_t>(g->voxels()));
  const std::size_t un = static_cast<std::size_t>(n);
  std::size_t at = 0;
  if (type == VolumeSourceType::kMarschnerLobb) {
    std::vector<double> xy(un * un);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        xy[static_cast<std::size_t>(j) * un + static_cast<std::size_t>(i)] =
            ml_xy(field_coordinate(i, n), field_coordinate(j, n));
      }
    }
    for (int k = 0; k < n; ++k) {
      const double z = ml_z(field_coordinate(k, n));
      for (const double t : xy) g->values[at++] = quantize(normalized(ml_combine(z, t), range));
    }
    return g;
  }
  std::vector<std::array<double, kHeatCount>> f[3];
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < n; ++i) f[a].push_back(heat_factors(a, field_coordinate(i, n)));
  }
  for (std::size_t k = 0; k < un; ++k) {
    for (std::size_t j = 0; j < un; ++j) {
      for (std::size_t i = 0; i < un; ++i) {
        g->values[at++] = quantize(normalized(heat_combine(f[0][i], f[1][j], f[2][k]), range));
      }
    }
  }
  return g;
}

std::optional<TransferFunction> transfer_preset(std::string_view name) {
  TransferFunction tf;
  if (name == "grey") {
    // Grey level and opacity both follow the value.
    tf.points = {{0.0, {0.0, 0.0, 0.0}, 0.0}, {1.0, {1.0, 1.0, 1.0}, 1.0}};
  } else if (name == "bone") {
    // Soft tissue and air transparent; from 0.3 up an ivory that turns
    // opaque white by 0.5 (a skull's bone at the data's default range).
    tf.points = {{0.0, {0.0, 0.0, 0.0}, 0.0},
                 {0.3, {0.85, 0.75, 0.6}, 0.0},
                 {0.4, {0.95, 0.9, 0.8}, 0.6},
                 {0.5, {1.0, 0.98, 0.94}, 0.95},
                 {1.0, {1.0, 1.0, 1.0}, 1.0}};
  } else if (name == "ml") {
    // Marschner-Lobb: faint blue low values, a bright opaque band at the
    // classic 0.5 isovalue whose ripples (the rings) show as colour and
    // thickness, and faint red above; values near 0 and 1 transparent.
    tf.points = {{0.0, {0.1, 0.2, 0.6}, 0.0},   {0.3, {0.2, 0.5, 1.0}, 0.04},
                 {0.45, {0.9, 0.9, 0.3}, 0.1},  {0.5, {1.0, 0.6, 0.1}, 0.7},
                 {0.55, {0.9, 0.25, 0.1}, 0.1}, {0.7, {0.8, 0.1, 0.3}, 0.04},
                 {1.0, {1.0, 1.0, 1.0}, 0.0}};
  } else {
    return std::nullopt;
  }
  return tf;
}

Volume procedural_volume(VolumeSourceType type, int n, std::string_view preset) {
  Volume v;
  v.source = type;
  v.grid = procedural_grid(type, n);
  const double s = 2.0 / (n - 1);
  v.spacing = {s, s, s};
  v.origin = {-1.0, -1.0, -1.0};
  const auto tf = transfer_preset(preset);
  BEAMCAST_CHECK(tf, "unknown transfer preset " + std::string(preset));
  v.transfer = *tf;
  return v;
}

std::array<int, 3> volume_level_dims(const std::array<int, 3>& dims, int level) {
  std::array<int, 3> d = dims;
  for (int l = 0; l < level; ++l) {
    for (int& n : d) n = std::max(2, (n + 1) / 2);
  }
  return d;
}

namespace {

// One level up: each voxel from its at most 8 children below.
VolumeGrid halve(const VolumeGrid& g, VolumePyramid how) {
  VolumeGrid out;
  out.dims = volume_level_dims(g.dims, 1);
  out.values.resize(static_cast<std::size_t>(out.voxels()));
  // The children of voxel I on an axis: [first, last].
  auto children = [](int axis_n, int axis_out, int I, int* first, int* last) {
    if (axis_out == axis_n) {  // an axis of 2 stays
      *first = *last = I;
      return;
    }
    *first = 2 * I;
    *last = std::min(2 * I + 1, axis_n - 1);
  };
  std::size_t at = 0;
  for (int K = 0; K < out.dims[2]; ++K) {
    int k0, k1;
    children(g.dims[2], out.dims[2], K, &k0, &k1);
    for (int J = 0; J < out.dims[1]; ++J) {
      int j0, j1;
      children(g.dims[1], out.dims[1], J, &j0, &j1);
      for (int I = 0; I < out.dims[0]; ++I) {
        int i0, i1;
        children(g.dims[0], out.dims[0], I, &i0, &i1);
        std::uint32_t sum = 0, nonzero_sum = 0, max = 0;
        int count = 0, nonzero = 0;
        for (int k = k0; k <= k1; ++k) {
          for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
              const std::uint32_t q =
                  g.values[(static_cast<std::size_t>(k) * g.dims[1] + j) * g.dims[0] + i];
              sum += q;
              ++count;
              max = std::max(max, q);
              if (q != 0) {
                nonzero_sum += q;
                ++nonzero;
              }
            }
          }
        }
        std::uint32_t v = max;
        if (how == VolumePyramid::kAverage) {
          v = (sum + count / 2) / count;  // rounded to nearest
        } else if (how == VolumePyramid::kNonZero) {
          v = nonzero == 0 ? 0 : (nonzero_sum + nonzero / 2) / nonzero;
        }
        out.values[at++] = static_cast<std::uint16_t>(v);
      }
    }
  }
  return out;
}

}  // namespace

std::shared_ptr<const VolumeGrid> volume_level(const VolumeGrid& g, int level, VolumePyramid how) {
  BEAMCAST_CHECK(level >= 0, "negative pyramid level");
  auto out = std::make_shared<VolumeGrid>(g);
  for (int l = 0; l < level; ++l) *out = halve(*out, how);
  return out;
}

}  // namespace beamcast
