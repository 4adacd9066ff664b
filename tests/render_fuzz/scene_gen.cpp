#include "tests/render_fuzz/scene_gen.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace beamcast::render_fuzz {
namespace {

using nlohmann::json;

// Numbers that have broken or could break derived quantities: zeros, the
// subnormal range, float's and double's edges, the limits' edges
// (max_abs_coordinate 1e12, the 1e-15 length floor, the 1e30 flux cap).
constexpr std::array<double, 36> kExtremes{
    0.0, -0.0, 5e-324, 1e-310, 2.2250738585072014e-308, 2.2250738585072019e-308, 1e-300,
    1e-200, 1e-100, 1e-45, 1.2e-38, 1e-38, 1e-31, 1e-30, 1e-16, 1e-15, 1.1e-15, 1e-12,
    1e-9, 1e-6, 1e6, 1e9, 1e12, 1.0000000000001e12, 1e13, 1e15, 1e30, 1.0000001e30,
    3.4e38, 3.5e38, 1e39, 1e100, 1e200, 1e300, 1.7976931348623157e308, 65504.0};

// splitmix64: small, fast, the same sequence everywhere.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double u() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  std::int64_t below(std::int64_t n) { return static_cast<std::int64_t>(next() % static_cast<std::uint64_t>(n)); }
  std::int64_t in(std::int64_t lo, std::int64_t hi) { return lo + below(hi - lo + 1); }  // [lo, hi]
  bool chance(double p) { return u() < p; }
  double range(double lo, double hi) { return lo + (hi - lo) * u(); }
  double log_range(double lo, double hi) { return std::exp(range(std::log(lo), std::log(hi))); }
  template <typename T, std::size_t N>
  const T& pick(const std::array<T, N>& a) { return a[static_cast<std::size_t>(below(N))]; }

 private:
  std::uint64_t s_;
};

// One case's generator: `x_` is the chance that a number is replaced by an
// extreme one, `d_` the chance that a geometric construct is made
// near-degenerate.
class Gen {
 public:
  Gen(std::uint64_t seed) : r_(seed) {
    static constexpr std::array<double, 6> kRates{0.0, 0.0, 0.01, 0.03, 0.1, 0.3};
    x_ = r_.pick(kRates);
    d_ = r_.pick(kRates);
  }
  Rng& rng() { return r_; }

  double extreme() {
    const double v = r_.pick(kExtremes);
    return r_.chance(0.3) ? -v : v;
  }
  // A number: usually in [lo, hi], at rate x_ an extreme.
  double num(double lo, double hi) { return r_.chance(x_) ? extreme() : r_.range(lo, hi); }
  // A positive size, log-uniform in [lo, hi]; at rate x_ an extreme, at rate
  // x_ a legal but far-out one (log-uniform over the whole legal range of
  // lengths, [1e-15, max_abs_coordinate]).
  double size(double lo, double hi) {
    if (r_.chance(x_)) return extreme();
    if (r_.chance(x_)) return r_.log_range(1e-15, 1e12);
    return r_.log_range(lo, hi);
  }
  // An integer knob: usually in [lo, hi], at rate x_ just outside or far out.
  json integer(std::int64_t lo, std::int64_t hi) {
    if (r_.chance(x_)) {
      static constexpr std::array<double, 8> kOut{-1.0, 0.0, 1e9, 2147483648.0, 1e300, 7.0,
                                                   -2147483649.0, 9007199254740993.0};
      const int which = static_cast<int>(r_.below(3));
      if (which == 0) return lo - 1;
      if (which == 1) return hi + 1;
      return r_.pick(kOut);
    }
    return r_.in(lo, hi);
  }
  json coord() {
    if (r_.chance(x_)) return (r_.chance(0.5) ? -1.0 : 1.0) * r_.log_range(1e-15, 1e12);
    return num(-4.0, 4.0);
  }
  json point() { return json::array({coord(), coord(), coord()}); }
  json point_near(const json& p, double scale) {
    json q = p;
    for (auto& c : q) {
      if (c.is_number()) c = c.get<double>() + r_.range(-scale, scale);
    }
    return q;
  }
  // A direction: nonzero in ordinary cases; zero, subnormal, huge or
  // axis-aligned at rate d_.
  json direction() {
    if (r_.chance(d_)) {
      static constexpr std::array<double, 7> kScale{0.0, 5e-324, 1e-310, 1e-300, 1e-160, 1e300, 1e-15};
      const double s = r_.pick(kScale);
      const int axis = static_cast<int>(r_.below(3));
      json v = json::array({0.0, 0.0, 0.0});
      v[axis] = r_.chance(0.5) ? s : -s;
      if (r_.chance(0.3)) v[(axis + 1) % 3] = s * 1e-3;
      return v;
    }
    return json::array({num(-1, 1), num(-1, 1), num(-1, 1)});
  }
  json color(double hi = 1.0) {
    return json::array({num(0, hi), num(0, hi), num(0, hi)});
  }
  // A unit-ish quaternion, or a tiny, huge or zero one at rate d_.
  json quaternion() {
    json q = json::array({r_.range(-1, 1), r_.range(-1, 1), r_.range(-1, 1), r_.range(-1, 1)});
    if (r_.chance(d_)) {
      static constexpr std::array<double, 6> kScale{0.0, 1e-310, 1e-200, 1e-160, 1e150, 1e300};
      const double s = r_.pick(kScale);
      for (auto& c : q) c = c.get<double>() * s;
    }
    return q;
  }
  // Two edge vectors: independent, or almost parallel, or one of zero length.
  std::pair<json, json> edges() {
    const double a = size(0.1, 4), b = size(0.1, 4);
    json u = json::array({a, 0.0, 0.0});
    json v = json::array({0.0, 0.0, b});
    if (r_.chance(d_)) {
      static constexpr std::array<double, 7> kSin{0.0, 1e-300, 1e-17, 1e-12, 1e-10, 1e-9, 1.1e-9};
      const double s = r_.pick(kSin);
      v = json::array({b, 0.0, b * s});  // sin(angle) ~ s
      if (r_.chance(0.3)) u = json::array({0.0, 0.0, 0.0});
    }
    if (r_.chance(0.5)) std::swap(u, v);
    return {u, v};
  }
  json density() {
    switch (r_.below(6)) {
      case 0: {
        static constexpr std::array<const char*, 5> kNames{"abe", "shell", "linear", "quadratic", "gaussian"};
        return r_.pick(kNames);
      }
      case 1: return {{"type", "gaussian"}, {"sigma", size(0.01, 10)}};
      case 2: {
        json s = json::array();
        const std::int64_t n = r_.in(2, 12);
        for (std::int64_t i = 0; i < n; ++i) s.push_back(num(0, 2));
        return {{"type", "table"}, {"samples", s}};
      }
      default: return "linear";
    }
  }
  json beam() {
    json b;
    if (r_.chance(0.5)) {
      b = {{"type", "sphere"}, {"center", point()}};
    } else {
      const json p0 = point();
      json p1 = r_.chance(d_) ? point_near(p0, r_.pick(std::array<double, 4>{0.0, 1e-300, 1e-12, 1e-9})) : point();
      b = {{"type", "capsule"}, {"p0", p0}, {"p1", p1}};
      if (r_.chance(0.5)) b["caps"] = {r_.chance(0.5), r_.chance(0.5)};
    }
    b["radius"] = size(0.05, 3);
    if (r_.chance(0.5)) b["color"] = color(2);
    if (r_.chance(0.5)) b["intensity"] = size(0.1, 4);
    if (r_.chance(0.6)) b["density"] = density();
    if (r_.chance(0.3)) b["emit"] = true;
    return b;
  }
  json material() {
    switch (r_.below(4)) {
      case 0: return {{"type", "mirror"}, {"reflectance", color()}};
      case 1: {
        json m = {{"type", "glass"}};
        if (r_.chance(0.7)) m["ior"] = r_.chance(x_) ? extreme() : r_.range(1.0001, 4.0);
        if (r_.chance(0.5)) m["tint"] = color();
        return m;
      }
      default: return {{"type", "diffuse"}, {"albedo", color()}};
    }
  }
  json occluder() {
    json o = json::object();
    switch (r_.below(7)) {
      case 0: o = {{"type", "plane"}, {"point", point()}, {"normal", direction()}}; break;
      case 1:
        o = {{"type", "box"}, {"center", point()},
             {"size", json::array({size(0.05, 4), r_.chance(d_) ? extreme() : size(0.05, 4), size(0.05, 4)})}};
        if (r_.chance(0.5)) o["rotation"] = quaternion();
        break;
      case 2: o = {{"type", "sphere"}, {"center", point()}, {"radius", size(0.05, 4)}}; break;
      case 3: {
        auto [u, v] = edges();
        o = {{"type", "quad"}, {"corner", point()}, {"edge_u", u}, {"edge_v", v}};
        if (r_.chance(0.4)) o["sides"] = r_.chance(0.5) ? 1 : 2;
        break;
      }
      case 4:
        o = {{"type", "mesh"}, {"file", "meshes/torus.obj"}};
        if (r_.chance(0.6)) o["translate"] = point();
        if (r_.chance(0.6)) {
          o["scale"] = r_.chance(0.5) ? json(size(0.1, 3))
                                      : json::array({size(0.1, 3), size(0.1, 3), r_.chance(d_) ? extreme() : size(0.1, 3)});
        }
        if (r_.chance(0.5)) o["rotation"] = quaternion();
        break;
      case 5: {
        json spheres = json::array();
        const std::int64_t n = r_.in(1, 4);
        for (std::int64_t i = 0; i < n; ++i) {
          json c = json::array();
          for (int k = 0; k < 6; ++k) c.push_back(num(-2, 2));
          json s = {{"center", point()}, {"radius", size(0.1, 3)}, {"coefficients", c}};
          if (r_.chance(0.4)) s["rotation"] = quaternion();
          if (r_.chance(0.25)) {
            json c2 = json::array();
            for (int k = 0; k < 6; ++k) c2.push_back(num(-2, 2));
            s["coefficients2"] = c2;
            s["crease"] = r_.chance(0.5) ? "min" : "max";
          }
          spheres.push_back(s);
        }
        o = {{"type", "slim"}, {"spheres", spheres}};
        if (r_.chance(0.3)) o["translate"] = point();
        if (r_.chance(0.3)) o["scale"] = size(0.1, 3);
        if (r_.chance(0.3)) o["rotation"] = quaternion();
        return o;  // SLIM takes a diffuse material only
      }
      default: o = {{"type", "plane"}, {"point", json::array({0, -1, 0})}, {"normal", json::array({0, 1, 0})}};
    }
    if (r_.chance(0.4)) {
      o["material"] = material();
    } else if (r_.chance(0.3)) {
      o["albedo"] = color();
    }
    return o;
  }
  json light() {
    json l;
    switch (r_.below(3)) {
      case 0: l = {{"type", "point"}, {"position", point()}}; break;
      case 1: {
        l = {{"type", "spot"}, {"position", point()}, {"direction", direction()}};
        const double outer = r_.chance(x_) ? extreme() : r_.range(1e-3, 180);
        l["outer_deg"] = outer;
        if (r_.chance(0.6)) l["inner_deg"] = r_.chance(x_) ? extreme() : r_.range(0, std::fabs(outer));
        break;
      }
      default: {
        auto [u, v] = edges();
        l = {{"type", "quad"}, {"corner", point()}, {"edge_u", u}, {"edge_v", v}};
        if (r_.chance(0.4)) {
          l["radiance"] = color(10);
          return l;
        }
      }
    }
    if (r_.chance(0.7)) l["power"] = size(0.1, 100);
    if (r_.chance(0.4)) l["color"] = color();
    return l;
  }
  json gi() {
    json g = json::object();
    // Photon counts mostly small; sometimes at the server's limits (refused by
    // the cost estimate or max_photons).
    auto photons = [&] {
      if (r_.chance(0.05)) return json(r_.pick(std::array<std::int64_t, 4>{100000, 1000000, 4000000, 4000001}));
      return json(r_.in(0, 2000));
    };
    g["photons"] = photons();
    g["caustic_photons"] = r_.chance(0.5) ? photons() : json(0);
    if (r_.chance(0.4)) g["radius"] = r_.chance(0.2) ? json(0) : json(size(1e-3, 4));
    if (r_.chance(0.2)) g["caustic_radius"] = size(1e-3, 1);
    if (r_.chance(0.3)) g["kernel"] = r_.pick(std::array<const char*, 3>{"box", "cone", "epanechnikov"});
    if (r_.chance(0.3)) g["seed"] = r_.in(0, 1000);
    if (r_.chance(0.4)) g["max_depth"] = integer(1, 64);
    if (r_.chance(0.3)) g["direct"] = r_.chance(0.5) ? "photons" : "shadow_maps";
    if (r_.chance(0.3)) g["direct_samples"] = integer(1, 16);
    if (r_.chance(0.2)) g["direct_interleave"] = r_.chance(0.5) ? 1 : 4;
    g["shadow_size"] = r_.chance(x_) ? integer(16, 2048) : json(r_.in(16, 32));
    if (r_.chance(0.2)) g["edge_correction"] = r_.chance(0.5);
    if (r_.chance(0.2)) g["light_antialias"] = r_.chance(0.5);
    if (r_.chance(0.3)) g["specular_samples"] = integer(1, 3);
    if (r_.chance(0.3)) g["splat_scale"] = integer(0, 8);
    if (r_.chance(0.3)) g["cluster"] = num(0, 1);
    if (r_.chance(0.15)) {
      g["lod"] = {{"near", size(0.1, 10)}, {"far", size(0.1, 20)}};
      if (r_.chance(0.5)) g["lod"]["groups"] = integer(1, 64);
    }
    return g;
  }
  json medium() {
    json m = json::object();
    // Dense media (up to the 1e6 limit) and almost empty ones (1e-300).
    auto sigma = [&] {
      if (r_.chance(0.2)) return json(r_.pick(std::array<double, 6>{0.0, 1e-300, 1e-12, 1e3, 1e6, 1e-6}));
      return json(size(0.01, 2));
    };
    if (r_.chance(0.8)) m["sigma_s"] = sigma();
    if (r_.chance(0.5)) m["sigma_a"] = sigma();
    if (r_.chance(0.3)) {
      m["k"] = r_.chance(x_) ? extreme() : r_.range(-0.999, 0.999);
    } else if (r_.chance(0.2)) {
      m["g"] = r_.range(-0.93, 0.93);
    }
    if (r_.chance(0.2)) m["beam_rule"] = r_.chance(0.5) ? "gauss2" : "midpoint";
    if (r_.chance(0.2)) m["beam_step"] = num(0.05, 8);
    if (r_.chance(0.2)) m["estimator"] = r_.chance(0.5) ? "beam" : "seed";
    if (r_.chance(0.3)) m["radius"] = r_.chance(0.2) ? json(0) : json(size(1e-3, 4));
    if (r_.chance(0.2)) m["radius_pixels"] = num(0, 16);
    if (r_.chance(0.2)) m["segments"] = integer(0, 16);
    return m;
  }
  json medium_region() {
    json r;
    switch (r_.below(4)) {
      case 0: {
        const json lo = point();
        json hi = lo;
        for (auto& c : hi) {
          if (c.is_number()) c = c.get<double>() + (r_.chance(d_) ? r_.pick(std::array<double, 4>{0.0, 1e-300, 1e-15, 1e-9}) : size(0.05, 4));
        }
        r = {{"type", "box"}, {"min", lo}, {"max", hi}};
        break;
      }
      case 1: r = {{"type", "sphere"}, {"center", point()}, {"radius", size(0.05, 4)}}; break;
      case 2:
        r = {{"type", "mesh"}, {"file", "meshes/torus.obj"}};
        if (r_.chance(0.5)) r["scale"] = size(0.1, 3);
        if (r_.chance(0.4)) r["rotation"] = quaternion();
        if (r_.chance(0.4)) r["translate"] = point();
        break;
      default: {
        // A tetrahedron, optionally flattened (coincident or coplanar points).
        json v = json::array({json::array({0, 0, 0}), json::array({1, 0, 0}), json::array({0, 1, 0}),
                              json::array({0, 0, 1})});
        const double s = size(0.1, 3);
        for (auto& p : v) {
          for (auto& c : p) c = c.get<double>() * s;
        }
        if (r_.chance(d_)) v[3] = r_.chance(0.5) ? v[0] : json::array({s * 0.5, s * 0.5, r_.pick(std::array<double, 3>{0.0, 1e-300, 1e-15})});
        json t = json::array({json::array({0, 2, 1}), json::array({0, 1, 3}), json::array({0, 3, 2}),
                              json::array({1, 2, 3})});
        r = {{"type", "mesh"}, {"vertices", v}, {"triangles", t}};
      }
    }
    auto sigma = [&] {
      if (r_.chance(0.25)) return json(r_.pick(std::array<double, 5>{0.0, 1e-300, 1e3, 1e6, 1e-9}));
      return json(size(0.05, 5));
    };
    r["sigma_s"] = sigma();
    if (r_.chance(0.4)) r["sigma_a"] = sigma();
    if (r_.chance(0.2)) r["k"] = r_.range(-0.9, 0.9);
    return r;
  }
  json volume() {
    json v;
    const bool ml = r_.chance(0.5);
    v["source"] = {{"type", ml ? "marschner_lobb" : "heat"}, {"resolution", integer(2, 12)}};
    if (r_.chance(0.4)) v["origin"] = point();
    if (r_.chance(0.5)) {
      v["spacing"] = r_.chance(0.5) ? json(size(0.01, 1))
                                    : json::array({size(0.01, 1), size(0.01, 1), r_.chance(d_) ? extreme() : size(0.01, 1)});
    }
    if (r_.chance(0.3)) v["rotation"] = quaternion();
    if (r_.chance(0.3)) {
      const double lo = num(-1, 0.5);
      v["range"] = json::array({lo, r_.chance(d_) ? lo + r_.pick(std::array<double, 3>{0.0, 1e-300, 1e-12}) : lo + size(0.1, 2)});
    }
    if (r_.chance(0.5)) {
      if (r_.chance(0.5)) {
        v["transfer"] = {{"preset", r_.pick(std::array<const char*, 3>{"grey", "bone", "ml"})}};
      } else {
        json pts = json::array();
        const std::int64_t n = r_.in(2, 5);
        double val = 0.0;
        for (std::int64_t i = 0; i < n; ++i) {
          pts.push_back(json::array({val, num(0, 2), num(0, 2), num(0, 2), r_.range(0, 1)}));
          val += r_.chance(d_) ? r_.pick(std::array<double, 3>{1e-300, 1e-16, 1e-9}) : r_.range(0.05, 0.4);
          if (val > 1.0) break;
        }
        v["transfer"] = {{"points", pts}};
      }
      if (r_.chance(0.4)) v["transfer"]["opacity_unit"] = size(1e-3, 1);
    }
    if (r_.chance(0.3)) v["intensity"] = size(0.1, 10);
    return v;
  }
  json volume_settings() {
    json s = json::object();
    if (r_.chance(0.5)) s["samples_per_voxel"] = size(0.1, 8);
    if (r_.chance(0.2)) s["opacity_correction"] = r_.chance(0.7);
    if (r_.chance(0.3)) s["ert"] = num(0.01, 1);
    if (r_.chance(0.2)) s["jitter"] = r_.chance(0.5);
    if (r_.chance(0.2)) s["skip_empty"] = r_.chance(0.5);
    if (r_.chance(0.3)) s["level"] = integer(0, 4);
    if (r_.chance(0.2)) s["pyramid"] = r_.pick(std::array<const char*, 3>{"average", "max", "nonzero"});
    if (r_.chance(0.2)) s["integration"] = r_.chance(0.5) ? "point" : "preintegrated";
    return s;
  }
  json slim_settings() {
    json s = json::object();
    if (r_.chance(0.5)) s["sampling"] = num(0.25, 16);
    if (r_.chance(0.5)) s["evaluation"] = r_.pick(std::array<const char*, 3>{"patch", "field", "blend"});
    if (r_.chance(0.3)) s["depth_threshold"] = num(0, 4);
    if (r_.chance(0.2)) s["fill_holes"] = r_.chance(0.5);
    if (r_.chance(0.2)) s["cull_backfaces"] = r_.chance(0.5);
    return s;
  }
  json frame_fields(json c) {
    if (r_.chance(0.3)) c["projection"] = r_.chance(0.5) ? "perspective" : "orthographic";
    if (r_.chance(0.3)) c["fov_y"] = r_.chance(x_) ? extreme() : r_.range(1e-6, 179.9999);
    if (r_.chance(0.2)) c["ortho_height"] = size(1e-3, 20);
    if (r_.chance(0.3)) {
      const double near = size(1e-4, 1);
      c["near"] = near;
      c["far"] = r_.chance(d_) ? near * r_.pick(std::array<double, 4>{1.0000001, 1e15, 1e14, 2.0}) : near + size(1, 1000);
    }
    return c;
  }
  json camera() {
    const std::int64_t kind = r_.below(10);
    if (kind == 7) {  // orbit
      json c = {{"rig", "orbit"}, {"count", r_.in(1, 3)}, {"width", r_.in(1, 8)}, {"height", r_.in(1, 8)}};
      if (r_.chance(0.5)) c["radius"] = size(0.5, 10);
      if (r_.chance(0.3)) c["axis"] = direction();
      if (r_.chance(0.3)) c["layout"] = r_.chance(0.5) ? "circle" : "sphere";
      else if (r_.chance(0.3)) c["elevation"] = r_.chance(x_) ? extreme() : r_.range(-89.999999, 89.999999);
      if (r_.chance(0.3)) c["target"] = point();
      return frame_fields(c);
    }
    if (kind == 8) {  // cubemap
      json c = {{"rig", "cubemap"}, {"size", r_.in(1, 6)}};
      if (r_.chance(0.5)) c["position"] = point();
      return c;
    }
    if (kind == 9) {  // stereo
      json pos = json::array({r_.range(-2, 2), r_.range(0, 3), r_.range(4, 8)});
      json c = {{"rig", "stereo"}, {"position", pos}, {"target", r_.chance(d_) ? point_near(pos, 1e-12) : point()},
                {"width", r_.in(1, 8)}, {"height", r_.in(1, 8)}};
      if (r_.chance(0.4)) c["eye_separation"] = size(1e-3, 1);
      if (r_.chance(0.3)) c["convergence"] = size(0.1, 20);
      return frame_fields(c);
    }
    json pos = r_.chance(0.8) ? json::array({r_.range(-3, 3), r_.range(-1, 4), r_.range(4, 9)}) : point();
    json c = {{"position", pos}, {"width", r_.chance(0.1) ? integer(1, 16) : json(r_.in(1, 16))},
              {"height", r_.in(1, 16)}};
    if (r_.chance(0.25)) {
      c["rotation"] = quaternion();
    } else {
      c["target"] = r_.chance(d_) ? point_near(pos, r_.pick(std::array<double, 3>{0.0, 1e-300, 1e-12})) : point();
      if (r_.chance(0.3)) {
        if (r_.chance(d_)) {  // up almost parallel to the view
          json up = json::array();
          for (int k = 0; k < 3; ++k) {
            up.push_back(c["target"][k].get<double>() - pos[k].get<double>() + r_.range(-1e-9, 1e-9));
          }
          c["up"] = up;
        } else {
          c["up"] = direction();
        }
      }
    }
    return frame_fields(c);
  }
  json output() {
    json o = json::object();
    if (r_.chance(0.5)) o["exposure"] = size(0.1, 10);
    if (r_.chance(0.3)) o["tone"] = r_.pick(std::array<const char*, 3>{"exponential", "reinhard", "clamp"});
    if (r_.chance(0.3)) o["bit_depth"] = r_.chance(0.5) ? 8 : 16;
    if (r_.chance(0.3)) o["supersample"] = integer(1, 4);
    return o;
  }
  json render() {
    json o = json::object();
    if (r_.chance(0.5)) o["method"] = r_.pick(std::array<const char*, 3>{"table", "closed_form", "march"});
    if (r_.chance(0.3)) {
      o["table_size"] = r_.chance(0.5) ? integer(8, 64) : json::array({integer(8, 64), integer(8, 64)});
    }
    if (r_.chance(0.3)) o["layout"] = r_.pick(std::array<const char*, 4>{"uniform", "chord", "warped", "chord_warped"});
    if (r_.chance(0.2)) o["filter"] = r_.chance(0.5) ? "hardware" : "shader";
    if (r_.chance(0.3)) o["samples"] = r_.chance(x_) ? integer(4, 1024) : json(2 * r_.in(2, 32));
    if (r_.chance(0.3)) o["rule"] = r_.chance(0.5) ? "midpoint" : "simpson";
    if (r_.chance(0.2)) o["f_table"] = integer(16, 4096);
    if (r_.chance(0.2)) o["near_parallel"] = r_.chance(0.5) ? "quadrature" : "none";
    return o;
  }

  json scene() {
    json s = json::object();
    if (r_.chance(0.5)) {
      const std::int64_t n = r_.in(1, 3);
      for (std::int64_t i = 0; i < n; ++i) s["beams"].push_back(beam());
    }
    if (r_.chance(0.6)) {
      const std::int64_t n = r_.in(1, 3);
      for (std::int64_t i = 0; i < n; ++i) s["occluders"].push_back(occluder());
    }
    if (r_.chance(0.35)) {
      const std::int64_t n = r_.in(1, 2);
      for (std::int64_t i = 0; i < n; ++i) s["lights"].push_back(light());
      if (r_.chance(0.9)) s["gi"] = gi();  // the default 2e5 photons are refused by cost
    }
    if (r_.chance(0.2)) {
      s["light"] = {{"direction", direction()}};
      if (r_.chance(0.5)) s["light"]["intensity"] = size(0.1, 4);
      if (r_.chance(0.5)) s["light"]["ambient"] = num(0, 1);
      if (r_.chance(0.3)) s["light"]["color"] = color(2);
    }
    if (r_.chance(0.25)) s["medium"] = medium();
    if (r_.chance(0.2)) {
      const std::int64_t n = r_.in(1, 2);
      for (std::int64_t i = 0; i < n; ++i) s["media"].push_back(medium_region());
    }
    if (r_.chance(0.2)) {
      s["volumes"].push_back(volume());
      if (r_.chance(0.2)) s["volumes"].push_back(volume());
      if (r_.chance(0.5)) s["volume"] = volume_settings();
    }
    if (r_.chance(0.15)) s["slim"] = slim_settings();
    if (r_.chance(0.2)) s["background"] = color(2);
    if (r_.chance(0.3)) s["output"] = output();
    if (r_.chance(0.3)) s["render"] = render();
    const std::int64_t n = r_.chance(0.8) ? 1 : 2;
    for (std::int64_t i = 0; i < n; ++i) s["cameras"].push_back(camera());
    return s;
  }

 private:
  Rng r_;
  double x_ = 0.0;
  double d_ = 0.0;
};

}  // namespace

FuzzCase make_case(std::uint64_t seed) {
  Gen g(seed);
  Rng& r = g.rng();
  FuzzCase c;
  c.seed = seed;
  const std::string id = "case-" + std::to_string(seed);
  json scene = g.scene();
  json params;
  const std::int64_t mode = r.below(8);
  if (mode == 0) {
    // Through the scene store: put, then render by id (with the scene's own
    // cameras or the request's).
    const std::string scene_id = "fuzz-" + std::to_string(seed);
    c.requests.push_back({{"id", id + "-put"}, {"method", "scene.put"},
                          {"params", {{"scene_id", scene_id}, {"scene", scene}}}});
    params = {{"scene_id", scene_id}};
    if (r.chance(0.3)) params["cameras"] = json::array({g.camera()});
  } else {
    params = {{"scene", scene}};
    if (mode == 1) params["cameras"] = json::array({g.camera()});
  }
  if (r.chance(0.1)) params["output"] = g.output();
  const std::int64_t extra = r.below(10);
  if (extra == 0) {
    params["quality"] = "auto";
    params["motion"] = r.chance(0.5) ? "moving" : "still";
    if (r.chance(0.5)) params["budget_ms"] = g.num(1, 100);
  } else if (extra == 1) {
    params["atlas"] = true;
  } else if (extra == 2) {
    params["stream"] = true;
  }
  c.requests.push_back({{"id", id}, {"method", "render"}, {"params", params}});
  return c;
}

}  // namespace beamcast::render_fuzz
