// Scene JSON -> Scene, validating every field. The format is documented in
// docs/scene-format.md; keep the two in step.
#include "protocol/scene_json.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <span>
#include <sstream>

#include "protocol/beams/beam_parse.hpp"
#include "protocol/camera.hpp"
#include "protocol/check.hpp"
#include "protocol/json_reader.hpp"
#include "protocol/kinds.hpp"
#include "protocol/lights/light_parse.hpp"
#include "protocol/occluders/occluder_parse.hpp"
#include "protocol/rigs.hpp"

namespace beamcast {

using nlohmann::json;
using namespace json_read;

namespace {

// ---- Small typed readers shared by the scene parts ----------------------------------

int read_int_in(const Node& n, std::int64_t lo, std::int64_t hi) {
  const std::int64_t v = read_integer(n);
  if (v < lo || v > hi) {
    fail("out_of_range", n.path,
         n.name() + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
             "], got " + std::to_string(v));
  }
  return static_cast<int>(v);
}

// An integer in [lo, hi] where hi is a named limit: above it is "limit_exceeded".
int read_int_limited(const Node& n, std::int64_t lo, std::int64_t hi, const char* limit_name) {
  const std::int64_t v = read_integer(n);
  if (v > hi) {
    fail("limit_exceeded", n.path,
         n.name() + " is " + std::to_string(v) + ", over the limit " + limit_name + " = " +
             std::to_string(hi));
  }
  if (v < lo) {
    fail("out_of_range", n.path,
         n.name() + " must be >= " + std::to_string(lo) + ", got " + std::to_string(v));
  }
  return static_cast<int>(v);
}

// "type", the kind's own keys (Kind::kFields), then the keys every element of
// its family shares, as one fixed array.
template <class Kind, std::size_t N>
auto kind_keys(const std::array<std::string_view, N>& shared) {
  std::array<std::string_view, 1 + Kind::kFields.size() + N> keys{"type"};
  std::copy(Kind::kFields.begin(), Kind::kFields.end(), keys.begin() + 1);
  std::copy(shared.begin(), shared.end(), keys.begin() + 1 + Kind::kFields.size());
  return keys;
}

// ---- Beams --------------------------------------------------------------------------

// The rig types: read by the parser, listed in hello's capabilities.
enum class RigKind { kOrbit, kCubemap, kStereo };
constexpr std::array<std::pair<std::string_view, RigKind>, 3> kRigKinds{
    {{"orbit", RigKind::kOrbit}, {"cubemap", RigKind::kCubemap}, {"stereo", RigKind::kStereo}}};

// "abe", "shell", ... (the built-in density names, quoted).
std::string quoted_density_names() {
  std::string names;
  for (std::string_view name : density_names()) {
    names += names.empty() ? "\"" : ", \"";
    names += name;
    names += '"';
  }
  return names;
}

Density parse_density(const Node& n, const SceneLimits& limits) {
  Density d;
  if (n.json().is_string()) {
    if (!density_from_name(n.json().get<std::string>(), &d)) {
      fail("invalid_value", n.path,
           "density must be one of " + quoted_density_names() + " or an object, got " +
               describe(n.json()));
    }
    return d;
  }
  if (!n.json().is_object()) {
    fail("wrong_type", n.path,
         "density must be a string (a built-in name) or an object, got " + describe(n.json()));
  }
  ObjectReader o(n, "a density");
  const Node type = o.required("type");
  const std::string t = read_string(type);
  if (t == "table") {
    o.allow_only({"type", "samples"});
    const Node samples = o.required("samples");
    const auto items = read_array(samples, limits.max_density_samples, "max_density_samples");
    if (items.size() < 2) {
      fail("invalid_value", samples.path,
           "samples must hold at least 2 values, got " + std::to_string(items.size()));
    }
    d.kind = DensityKind::kTable;
    bool any_positive = false;
    for (const Node& item : items) {
      d.samples.push_back(check_non_negative(item, read_number(item)));
      any_positive = any_positive || d.samples.back() > 0.0;
    }
    if (!any_positive) {
      fail("invalid_value", samples.path,
           "samples must not all be zero (the beam would be invisible)");
    }
    return d;
  }
  if (!density_from_name(t, &d)) {
    fail("invalid_value", type.path,
         "density type must be one of " + quoted_density_names() + ", \"table\", got " +
             describe(type.json()));
  }
  if (d.kind == DensityKind::kGaussian) {
    o.allow_only({"type", "sigma"});
    if (auto s = o.optional("sigma")) {
      d.sigma = read_number(*s);
      if (!(d.sigma > 0.0 && d.sigma <= 10.0)) {
        fail("out_of_range", s->path, "sigma must be in (0, 10], got " + format_number(d.sigma));
      }
    }
  } else {
    o.allow_only({"type"});
  }
  return d;
}

// A colour times a factor (intensity, a density's peak) at most
// kMaxRadiometric per channel, or out_of_range at `path`.
void check_radiometric_product(double factor, const Color& color, const std::string& path,
                               const char* what) {
  for (const double c : color) {
    if (!(c * factor <= kMaxRadiometric)) {
      fail("out_of_range", path,
           std::string(what) + " must be at most " + format_number(kMaxRadiometric) +
               " per channel (the GPU adds light in float), got " + format_number(c * factor));
    }
  }
}

// The fields every beam has; the kind's own (protocol/beams/) come after
// "type" in the allowed list and are read by its parse function.
constexpr std::array<std::string_view, 5> kBeamFields{"radius", "color", "intensity", "density",
                                                     "emit"};

Beam parse_beam(const Node& n, const SceneLimits& limits) {
  ObjectReader o(n, "a beam");
  Beam b;
  b.shape = parse_kind<BeamShape>(o.required("type"), [&](auto kind) {
    using Kind = typename decltype(kind)::type;
    o.allow_only(kind_keys<Kind>(kBeamFields));
    b.radius = read_size(o.required("radius"), limits);
    if (auto c = o.optional("color")) b.color = read_color(*c);
    if (auto i = o.optional("intensity")) b.intensity = read_radiometric(*i);
    if (auto d = o.optional("density")) b.density = parse_density(*d, limits);
    if (auto e = o.optional("emit")) b.emit = read_bool(*e);
    return Kind::parse(BeamParse{o, limits, b.radius});
  });
  check_radiometric_product(b.intensity * b.density.max_value(), b.color, o.path(),
                            "color x intensity x the density's peak");
  return b;
}

// ---- Occluders ----------------------------------------------------------------------

// {"type": "diffuse" | "mirror" | "glass", ...}; a diffuse material's
// albedo is the occluder's "albedo" (given in one place only).
Material parse_material(const Node& n, bool albedo_given, Color* albedo) {
  ObjectReader o(n, "a material");
  const Node type = o.required("type");
  Material m;
  m.type = read_enum<MaterialType>(type, {{"diffuse", MaterialType::kDiffuse},
                                          {"mirror", MaterialType::kMirror},
                                          {"glass", MaterialType::kGlass}});
  switch (m.type) {
    case MaterialType::kDiffuse:
      o.allow_only({"type", "albedo"});
      if (auto a = o.optional("albedo")) {
        if (albedo_given) {
          fail("invalid_value", a->path,
               "albedo is given twice: in the occluder and in its material; give it once");
        }
        *albedo = read_albedo(*a);
      }
      break;
    case MaterialType::kMirror:
      o.allow_only({"type", "reflectance"});
      if (auto r = o.optional("reflectance")) m.reflectance = read_albedo(*r);
      break;
    case MaterialType::kGlass:
      o.allow_only({"type", "ior", "tint"});
      if (auto i = o.optional("ior")) {
        m.ior = read_number(*i);
        // 1 would be no surface at all; above 4 no transparent material.
        if (!(m.ior > 1.0 && m.ior <= 4.0)) {
          fail("out_of_range", i->path, "ior must be in (1, 4], got " + format_number(m.ior));
        }
      }
      if (auto t = o.optional("tint")) m.tint = read_albedo(*t);
      break;
  }
  return m;
}

// The kind's own parse function (protocol/occluders/) reads its fields;
// "albedo" and "material" are common to every kind.
Occluder parse_occluder(const Node& n, const SceneLoadOptions& opts, std::int64_t* mesh_triangles,
                        std::int64_t* slim_spheres) {
  ObjectReader o(n, "an occluder");
  const Node type = o.required("type");
  Occluder occ;
  occ.shape = parse_occluder_shape(type, OccluderParse{o, opts, mesh_triangles, slim_spheres});
  const auto albedo = o.optional("albedo");
  if (albedo) occ.albedo = read_albedo(*albedo);
  if (auto m = o.optional("material")) occ.material = parse_material(*m, albedo.has_value(), &occ.albedo);
  if (std::holds_alternative<SlimOccluder>(occ.shape) && occ.material.type != MaterialType::kDiffuse) {
    // The slim passes blend points of one pixel into one diffuse G-buffer
    // texel; a mirror or glass SLIM surface has no GPU form yet.
    fail("invalid_value", o.path_of("material"), "slim surfaces are diffuse (material \"diffuse\")");
  }
  return occ;
}

// ---- Lights of the global-illumination path -------------------------------------------

// Every light has "color" (default white) and "power" (watts, default 1):
// flux = color x power. A quad may give "radiance" instead of both.
constexpr std::array<std::string_view, 2> kLightFields{"color", "power"};

// The most flux per channel a light may have, and the most radiance a quad
// light may have: photon powers, radiances and their products with the
// scene's factors stay finite in the GPU's floats (3.4e38; issue 43).
constexpr double kMaxLightValue = kMaxRadiometric;

void check_light_values(const Light& l, const std::string& path) {
  const double flux = std::max({l.flux[0], l.flux[1], l.flux[2]});
  const double radiance = std::visit([](const auto& k) { return k.radiance_scale(); }, l.shape) * flux;
  if (!(flux <= kMaxLightValue) || !(radiance <= kMaxLightValue)) {
    fail("out_of_range", path,
         "the light's flux (" + format_number(flux) + ") and radiance (" + format_number(radiance) +
             ") must each be at most " + format_number(kMaxLightValue) +
             " per channel: lower its power, color, radiance or intensity, or enlarge it");
  }
}

Light parse_gi_light(const Node& n, const SceneLimits& limits) {
  ObjectReader o(n, "a light");
  Light l;
  l.shape = parse_kind<LightShape>(o.required("type"), [&](auto kind) {
    using Kind = typename decltype(kind)::type;
    o.allow_only(kind_keys<Kind>(kLightFields));
    return Kind::parse(LightParse{o, limits});
  });
  Color color{1.0, 1.0, 1.0};
  double power = 1.0;
  const auto c = o.optional("color");
  const auto p = o.optional("power");
  if (c) color = read_color(*c);
  if (p) {
    power = read_number(*p);
    if (!(power >= 0.0)) {
      fail("out_of_range", p->path, "power must be >= 0 (watts), got " + format_number(power));
    }
  }
  l.flux = power * color;
  // Only kinds that list "radiance" in kFields (area lights) get here with it.
  if (auto r = o.optional("radiance")) {
    if (c || p) {
      fail("invalid_value", r->path,
           "give an area light either radiance or color and power, not both");
    }
    // Radiance is radiance_scale() x flux (a Lambertian emitter of radiance
    // L sends pi L area into its hemisphere).
    const double scale = std::visit([](const auto& k) { return k.radiance_scale(); }, l.shape);
    BEAMCAST_CHECK(scale > 0.0, "a light kind accepting radiance has an area");
    l.flux = (1.0 / scale) * read_color(*r);
  }
  check_light_values(l, o.path());
  return l;
}

// The light of each beam with "emit": true, after the scene's own lights.
void add_beam_lights(Scene* scene, const std::string& beams_path) {
  for (std::size_t i = 0; i < scene->beams.size(); ++i) {
    const Beam& b = scene->beams[i];
    if (!b.emit) continue;
    BeamEmitter e = BeamEmitter::from_beam(b.shape, b.radius, b.density, static_cast<int>(i));
    const double m = e.volume_mass();
    Light l{std::move(e), {}};
    // The glow is measured in radii (docs/scene-format.md, Units): per world
    // length it is color x intensity x f / radius.
    for (std::size_t k = 0; k < 3; ++k) {
      l.flux[k] = 4.0 * std::numbers::pi * b.color[k] * b.intensity * m / b.radius;
    }
    check_light_values(l, child_path(beams_path, i));
    scene->lights.push_back(std::move(l));
  }
}

// The direct-light pass's shadow maps, checked against max_shadow_texels
// (the scene's lights and gi settings together decide their size).
void check_shadow_budget(const Scene& scene, const SceneLimits& limits, const std::string& path) {
  if (!scene.has_gi() || scene.gi.direct != DirectLightMethod::kShadowMaps) return;
  std::int64_t points = 0;
  for (const Light& l : scene.lights) {
    points += std::visit(
        [&](const auto& kind) {
          return static_cast<std::int64_t>(kind.direct_points(scene.gi.direct_samples).size());
        },
        l.shape);
  }
  const std::int64_t size = scene.gi.shadow_size;
  const std::int64_t texels = points * 6 * size * size;
  if (texels > limits.max_shadow_texels) {
    fail("limit_exceeded", path,
         "the direct light's shadow maps need " + std::to_string(texels) + " texels (" +
             std::to_string(points) + " points x 6 faces x " + std::to_string(size) +
             "^2), over the limit max_shadow_texels = " + std::to_string(limits.max_shadow_texels) +
             ": lower gi.shadow_size or gi.direct_samples, or set gi.direct to \"photons\"");
  }
}

GiSettings parse_gi(const Node& n, const SceneLimits& limits) {
  ObjectReader o(n, "gi settings");
  o.allow_only({"photons", "caustic_photons", "radius", "kernel", "seed", "max_depth", "direct",
                "direct_samples", "direct_interleave", "shadow_size", "edge_correction",
                "splat_scale", "cluster",
                "light_antialias", "caustic_radius", "specular_samples", "specular_tracer",
                "lod"});
  GiSettings g;
  std::int64_t total = 0;
  auto count = [&](const Node& v) {
    const std::int64_t k = read_integer(v);
    if (k < 0) fail("out_of_range", v.path, v.name() + " must be >= 0, got " + std::to_string(k));
    if (k > limits.max_photons - total) {
      fail("limit_exceeded", v.path,
           "photons and caustic_photons together are over the limit max_photons = " +
               std::to_string(limits.max_photons) + " (" + v.name() + " is " + std::to_string(k) +
               ")");
    }
    total += k;
    return k;
  };
  if (auto v = o.optional("photons")) {
    g.photons = count(*v);
  } else {
    total += std::min(g.photons, limits.max_photons);
    g.photons = std::min(g.photons, limits.max_photons);
  }
  if (auto v = o.optional("caustic_photons")) {
    g.caustic_photons = count(*v);
  } else {
    g.caustic_photons = std::min(g.caustic_photons, limits.max_photons - total);
  }
  if (auto v = o.optional("radius")) {
    g.radius = read_number(*v);
    if (!(g.radius >= 0.0 && g.radius <= limits.max_abs_coordinate)) {
      fail("out_of_range", v->path,
           "radius must be in [0, " + format_number(limits.max_abs_coordinate) +
               "] (0: chosen from the scene size; the upper bound is max_abs_coordinate), got " +
               format_number(g.radius));
    }
  }
  if (auto v = o.optional("caustic_radius")) {
    g.caustic_radius = read_number(*v);
    if (!(g.caustic_radius >= 0.0 && g.caustic_radius <= limits.max_abs_coordinate)) {
      fail("out_of_range", v->path,
           "caustic_radius must be in [0, " + format_number(limits.max_abs_coordinate) +
               "] (0: from the caustic photon count; the upper bound is max_abs_coordinate), "
               "got " + format_number(g.caustic_radius));
    }
  }
  if (auto v = o.optional("kernel")) {
    g.kernel = read_enum<SplatKernel>(*v, {{"box", SplatKernel::kBox},
                                           {"cone", SplatKernel::kCone},
                                           {"epanechnikov", SplatKernel::kEpanechnikov}});
  }
  if (auto v = o.optional("seed")) {
    const std::int64_t s = read_integer(*v);
    if (s < 0) fail("out_of_range", v->path, "seed must be >= 0, got " + std::to_string(s));
    g.seed = static_cast<std::uint64_t>(s);
  }
  if (auto v = o.optional("max_depth")) g.max_depth = read_int_in(*v, 1, 64);
  if (auto v = o.optional("direct")) {
    g.direct = read_enum<DirectLightMethod>(
        *v, {{"shadow_maps", DirectLightMethod::kShadowMaps}, {"photons", DirectLightMethod::kPhotons}});
  }
  if (auto v = o.optional("direct_samples")) g.direct_samples = read_int_in(*v, 1, 256);
  if (auto v = o.optional("direct_interleave")) {
    const std::int64_t k = read_integer(*v);
    if (k != 1 && k != 4) {
      fail("out_of_range", v->path,
           "direct_interleave must be 1 (every point at every pixel) or 4 (a 2 x 2 pattern), got " +
               std::to_string(k));
    }
    g.direct_interleave = static_cast<int>(k);
  }
  if (auto v = o.optional("shadow_size")) g.shadow_size = read_int_in(*v, 16, 2048);
  if (auto v = o.optional("edge_correction")) g.edge_correction = read_bool(*v);
  if (auto v = o.optional("light_antialias")) g.light_antialias = read_bool(*v);
  if (auto v = o.optional("splat_scale")) g.splat_scale = read_int_in(*v, 0, 8);
  if (auto v = o.optional("cluster")) g.cluster = check_closed(*v, read_number(*v), 0.0, 1.0);
  if (auto v = o.optional("specular_samples")) g.specular_samples = read_int_in(*v, 1, 8);
  if (auto v = o.optional("specular_tracer")) {
    g.specular_tracer = read_enum<SpecularTracer>(
        *v, {{"auto", SpecularTracer::kAuto},
             {"gpu", SpecularTracer::kGpu},
             {"cpu", SpecularTracer::kCpu}});
  }
  if (auto v = o.optional("lod")) {
    ObjectReader lod(*v, "photon level of detail");
    lod.allow_only({"near", "far", "groups"});
    const Node near = lod.required("near");
    const Node far = lod.required("far");
    g.lod_near = check_closed(near, read_number(near), 0.0, limits.max_abs_coordinate);
    g.lod_far = check_closed(far, read_number(far), 0.0, limits.max_abs_coordinate);
    if (g.lod_near == g.lod_far) {
      fail("invalid_value", far.path, "far must differ from near (the detail's ramp has a width)");
    }
    g.lod_groups = 16;
    if (auto a = lod.optional("groups")) g.lod_groups = read_int_in(*a, 1, 1024);
  }
  return g;
}

// ---- Scene-wide settings ------------------------------------------------------------

DirectionalLight parse_light(const Node& n) {
  ObjectReader o(n, "a light");
  o.allow_only({"direction", "color", "intensity", "ambient"});
  DirectionalLight l;
  if (auto d = o.optional("direction")) l.direction = read_direction(*d);
  if (auto c = o.optional("color")) l.color = read_color(*c);
  if (auto i = o.optional("intensity")) l.intensity = read_radiometric(*i);
  if (auto a = o.optional("ambient")) l.ambient = check_closed(*a, read_number(*a), 0.0, 1.0);
  check_radiometric_product(l.intensity, l.color, n.path, "color x intensity");
  return l;
}

OutputSettings parse_output(const Node& n) {
  ObjectReader o(n, "output settings");
  o.allow_only({"exposure", "tone", "bit_depth", "supersample"});
  OutputSettings out;
  if (auto e = o.optional("exposure")) out.exposure = check_positive(*e, read_number(*e));
  if (auto t = o.optional("tone")) {
    out.tone = read_enum<ToneCurve>(*t, {{"exponential", ToneCurve::kExponential},
                                         {"reinhard", ToneCurve::kReinhard},
                                         {"clamp", ToneCurve::kClamp}});
  }
  if (auto b = o.optional("bit_depth")) {
    const std::int64_t v = read_integer(*b);
    if (v != 8 && v != 16) {
      fail("invalid_value", b->path, "bit_depth must be 8 or 16, got " + std::to_string(v));
    }
    out.bit_depth = static_cast<int>(v);
  }
  if (auto k = o.optional("supersample")) out.supersample = read_int_in(*k, 1, kMaxSupersample);
  return out;
}

RenderSettings parse_render(const Node& n, const SceneLimits& limits) {
  ObjectReader o(n, "render settings");
  o.allow_only(
      {"method", "table_size", "layout", "filter", "f_table", "samples", "rule", "near_parallel"});
  RenderSettings r;
  if (auto m = o.optional("method")) {
    r.method = read_enum<IntegrationMethod>(*m, {{"table", IntegrationMethod::kTable},
                                                 {"closed_form", IntegrationMethod::kClosedForm},
                                                 {"march", IntegrationMethod::kMarch}});
  }
  if (auto l = o.optional("layout")) {
    r.layout = read_enum<TableLayout>(*l, {{"uniform", TableLayout::kUniform},
                                           {"chord", TableLayout::kChord},
                                           {"warped", TableLayout::kWarped},
                                           {"chord_warped", TableLayout::kChordWarped}});
  }
  if (auto f = o.optional("filter")) {
    r.filter = read_enum<TableFilter>(*f, {{"hardware", TableFilter::kHardware},
                                           {"shader", TableFilter::kShader}});
  }
  if (auto ru = o.optional("rule")) {
    r.rule = read_enum<MarchRule>(*ru, {{"midpoint", MarchRule::kMidpoint},
                                        {"simpson", MarchRule::kSimpson}});
  }
  if (auto np = o.optional("near_parallel")) {
    r.near_parallel = read_enum<NearParallel>(*np, {{"quadrature", NearParallel::kQuadrature},
                                                    {"none", NearParallel::kNone}});
  }
  if (auto n_samples = o.optional("samples")) {
    r.samples = read_int_in(*n_samples, 4, 1024);
    if (r.rule == MarchRule::kSimpson && r.samples % 2 != 0) {
      fail("invalid_value", n_samples->path,
           "Simpson's rule needs an even number of sub-intervals, got " +
               std::to_string(r.samples));
    }
  }
  if (auto t = o.optional("table_size")) {
    if (t->json().is_array()) {
      if (t->json().size() != 2) {
        fail("wrong_type", t->path,
             "table_size must be an integer or an array of 2 integers, got " + describe(t->json()));
      }
      r.table_d = read_int_limited(Node{&t->json()[0], child_path(t->path, 0)}, limits.min_table,
                                   limits.max_table, "max_table");
      r.table_s = read_int_limited(Node{&t->json()[1], child_path(t->path, 1)}, limits.min_table,
                                   limits.max_table, "max_table");
    } else {
      r.table_d = r.table_s = read_int_limited(*t, limits.min_table, limits.max_table, "max_table");
    }
  }
  // 4096: what the renderer's table (render/lut.cpp) and its 1D texture take.
  if (auto f = o.optional("f_table")) r.f_table = read_int_in(*f, 16, 4096);
  return r;
}

// ---- Cameras ------------------------------------------------------------------------

std::string read_camera_name(const Node& n) {
  const std::string s = read_string(n);
  bool ok = !s.empty() && s.size() <= 64 && s != "." && s != "..";
  for (char c : s) {
    ok = ok && ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                c == '_' || c == '.' || c == '-');
  }
  if (!ok) {
    fail("invalid_value", n.path,
         "name must be 1 to 64 characters from [A-Za-z0-9_.-] (and not \".\" or \"..\"), got " +
             describe(n.json()));
  }
  return s;
}

// Checks that the look-at frame is well defined (camera_basis relies on it).
void check_look_at(const Camera& c, const Node* target, const Node* up) {
  Vec3 forward{0.0, 0.0, -1.0};
  if (target) {
    const Vec3 d = *c.target - c.position;
    const double scale = std::max({1.0, length(c.position), length(*c.target)});
    if (!(length(d) > 1e-12 * scale)) {
      fail("invalid_value", target->path,
           "target must differ from position (the view direction is undefined)");
    }
    forward = normalize(d);
  }
  if (!normalizable(c.up)) {
    fail("invalid_value", up ? up->path : std::string(), "up must be a nonzero vector");
  }
  // camera_basis normalizes cross(forward, up) without normalizing up first.
  if (length(cross(forward, normalize(c.up))) < 1e-6 || !normalizable(cross(forward, c.up))) {
    fail("invalid_value", up ? up->path : (target ? target->path : std::string()),
         "up must not be parallel to the view direction (target - position)");
  }
}

}  // namespace

OutputSettings parse_output_settings(const json& j, const std::string& path) {
  return parse_output(Node{&j, path});
}

namespace {

// Every camera field except the size check: rigs check the size of the frames
// they make themselves (a cube map's size is its own field).
Camera parse_camera_fields(const json& j, const std::string& path, const SceneLimits& limits) {
  const Node n{&j, path};
  ObjectReader o(n, "a camera");
  o.allow_only({"name", "position", "target", "rotation", "up", "projection", "fov_y",
                "ortho_height", "near", "far", "width", "height"});
  Camera c;
  if (auto v = o.optional("name")) c.name = read_camera_name(*v);
  if (auto v = o.optional("position")) c.position = read_point(*v, limits);

  const auto target = o.optional("target");
  const auto rotation = o.optional("rotation");
  const auto up = o.optional("up");
  if (target && rotation) {
    fail("conflicting_fields", rotation->path,
         "a camera takes either \"target\" or \"rotation\", not both");
  }
  if (rotation && up) {
    fail("conflicting_fields", up->path,
         "\"up\" is only used with \"target\"; \"rotation\" already fixes the up direction");
  }
  if (target) c.target = read_point(*target, limits);
  if (rotation) c.rotation = read_quaternion(*rotation);
  if (up) c.up = read_vec3(*up);
  if (!rotation) check_look_at(c, target ? &*target : nullptr, up ? &*up : nullptr);

  if (auto v = o.optional("projection")) {
    c.projection = read_enum<Projection>(*v, {{"perspective", Projection::kPerspective},
                                              {"orthographic", Projection::kOrthographic}});
  }
  if (auto v = o.optional("fov_y")) c.fov_y_deg = check_open(*v, read_number(*v), 0.0, 180.0);
  if (auto v = o.optional("ortho_height")) c.ortho_height = read_size(*v, limits);
  if (auto v = o.optional("near")) c.near_plane = check_positive(*v, read_number(*v));
  const auto far = o.optional("far");
  if (far) c.far_plane = read_number(*far);
  if (!(c.far_plane > c.near_plane) || c.far_plane / c.near_plane > 1e15) {
    const std::string where = far ? far->path : o.path_of("near");
    fail("out_of_range", where,
         "far must be > near and far / near <= 1e15, got near " + format_number(c.near_plane) +
             " and far " + format_number(c.far_plane));
  }

  if (auto v = o.optional("width")) c.width = read_int_limited(*v, 1, limits.max_width, "max_width");
  if (auto v = o.optional("height")) {
    c.height = read_int_limited(*v, 1, limits.max_height, "max_height");
  }
  return c;
}

// Where a camera's (or a rig's) width and height came from: the field, or the
// object itself when the default applied.
std::string size_path(const json& j, const std::string& path, const char* key) {
  return j.is_object() && j.contains(key) ? child_path(path, key) : path;
}

}  // namespace

void check_frame_size(std::int64_t width, std::int64_t height, const SceneLimits& limits,
                      const std::string& width_path, const std::string& height_path,
                      std::string_view what) {
  const std::string w = std::to_string(width), h = std::to_string(height);
  // A path that ends in the object rather than a size field: the default applied.
  const auto dflt = [](const std::string& p) {
    return p.ends_with("/width") || p.ends_with("/height") || p.ends_with("/size") ? ""
                                                                                   : " (the default)";
  };
  if (width > limits.max_width) {
    fail("limit_exceeded", width_path,
         std::string(what) + " width " + w + dflt(width_path) +
             " is over the limit max_width = " + std::to_string(limits.max_width));
  }
  if (height > limits.max_height) {
    fail("limit_exceeded", height_path,
         std::string(what) + " height " + h +
             dflt(height_path) +
             " is over the limit max_height = " + std::to_string(limits.max_height));
  }
  if (width * height > limits.max_pixels) {
    fail("limit_exceeded", width_path,
         std::string(what) + " of " + w + " x " + h + " = " + std::to_string(width * height) +
             " pixels is over the limit max_pixels = " + std::to_string(limits.max_pixels));
  }
}

void check_supersampled_size(const std::vector<Camera>& cameras, int supersample,
                             const SceneLimits& limits, const std::string& path) {
  if (supersample <= 1) return;
  for (const Camera& c : cameras) {
    check_frame_size(static_cast<std::int64_t>(c.width) * supersample,
                     static_cast<std::int64_t>(c.height) * supersample, limits, path, path,
                     "supersampled camera");
  }
}

AtlasGrid atlas_grid(const std::vector<std::pair<int, int>>& sizes) {
  AtlasGrid g;
  const int k = static_cast<int>(sizes.size());
  if (k == 0) return g;
  g.columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(k))));
  g.rows = (k + g.columns - 1) / g.columns;
  for (const auto& [w, h] : sizes) {
    g.cell_width = std::max(g.cell_width, w);
    g.cell_height = std::max(g.cell_height, h);
  }
  return g;
}

Camera parse_camera(const json& j, const std::string& path, const SceneLimits& limits) {
  Camera c = parse_camera_fields(j, path, limits);
  check_frame_size(c.width, c.height, limits, size_path(j, path, "width"),
                   size_path(j, path, "height"), "camera");
  return c;
}


namespace {

// ---- Camera rigs (expansion math in rigs.cpp) ---------------------------------------

// The camera fields a rig copies to every camera it makes.
const std::initializer_list<std::string_view> kIntrinsics = {
    "projection", "fov_y", "ortho_height", "near", "far", "width", "height"};

// Reads the rig's intrinsic fields through parse_camera, so they get the same
// rules and the same error paths as in a plain camera.
Camera read_rig_base(const json& j, const std::string& path, const SceneLimits& limits) {
  json subset = json::object();
  for (std::string_view key : kIntrinsics) {
    if (auto it = j.find(key); it != j.end()) subset[std::string(key)] = *it;
  }
  return parse_camera_fields(subset, path, limits);
}

int read_rig_count(const ObjectReader& o, const SceneLimits& limits) {
  const Node n = o.required("count");
  return read_int_limited(n, 1, limits.max_cameras, "max_cameras");
}

std::vector<Camera> parse_orbit(const ObjectReader& o, const json& j, const std::string& prefix,
                                const SceneLimits& limits) {
  o.allow_only({"rig", "name", "count", "target", "radius", "axis", "layout", "elevation", "start",
                "projection", "fov_y", "ortho_height", "near", "far", "width", "height"});
  OrbitRig rig;
  rig.count = read_rig_count(o, limits);
  if (auto v = o.optional("target")) rig.target = read_point(*v, limits);
  if (auto v = o.optional("radius")) rig.radius = read_size(*v, limits);
  if (auto v = o.optional("axis")) rig.axis = normalize(read_direction(*v));
  if (auto v = o.optional("layout")) {
    rig.layout = read_enum<OrbitRig::Layout>(
        *v, {{"circle", OrbitRig::Layout::kCircle}, {"sphere", OrbitRig::Layout::kSphere}});
  }
  if (auto v = o.optional("elevation")) {
    if (rig.layout != OrbitRig::Layout::kCircle) {
      fail("conflicting_fields", v->path, "elevation applies to the circle layout only");
    }
    // At +-90 degrees every camera sits on the axis and looks along its own up.
    rig.elevation_deg = check_open(*v, read_number(*v), -90.0, 90.0);
  }
  if (auto v = o.optional("start")) rig.start_deg = read_number(*v);
  const Camera base = read_rig_base(j, o.path(), limits);
  check_frame_size(base.width, base.height, limits, size_path(j, o.path(), "width"),
                   size_path(j, o.path(), "height"), "orbit camera");
  std::vector<Camera> cams = expand_orbit(rig, base, prefix);
  for (const Camera& c : cams) {
    // Rounding can still bring a camera within 1e-6 of its up axis (elevation
    // a hair under 90); the same rule as a plain look-at camera.
    if (length(cross(normalize(*c.target - c.position), rig.axis)) < 1e-6) {
      fail("invalid_value", o.path_of("elevation"),
           "orbit camera " + c.name + " looks along the axis (its up direction)");
    }
  }
  return cams;
}

std::vector<Camera> parse_cubemap(const ObjectReader& o, const json& j, const std::string& prefix,
                                  const SceneLimits& limits) {
  o.allow_only({"rig", "name", "position", "size", "near", "far"});
  CubemapRig rig;
  if (auto v = o.optional("position")) rig.position = read_point(*v, limits);
  Camera base = read_rig_base(j, o.path(), limits);
  if (auto v = o.optional("size")) base.width = read_int_limited(*v, 1, std::numeric_limits<int>::max(), "size");
  const std::string where = size_path(j, o.path(), "size");
  check_frame_size(base.width, base.width, limits, where, where, "cube map face");
  return expand_cubemap(rig, base, prefix);
}

std::vector<Camera> parse_stereo(const ObjectReader& o, const json& j, const std::string& prefix,
                                 const SceneLimits& limits) {
  o.allow_only({"rig", "name", "position", "target", "up", "eye_separation", "convergence",
                "projection", "fov_y", "ortho_height", "near", "far", "width", "height"});
  StereoRig rig;
  Camera centre;
  if (auto v = o.optional("position")) rig.position = centre.position = read_point(*v, limits);
  const Node target = o.required("target");
  rig.target = read_point(target, limits);
  centre.target = rig.target;
  const auto up = o.optional("up");
  if (up) rig.up = centre.up = read_vec3(*up);
  check_look_at(centre, &target, up ? &*up : nullptr);
  if (auto v = o.optional("eye_separation")) {
    rig.separation = check_non_negative(*v, read_number(*v));
    if (rig.separation > limits.max_abs_coordinate) {
      fail("out_of_range", v->path,
           "eye_separation must be <= " + format_number(limits.max_abs_coordinate));
    }
  }
  if (auto v = o.optional("convergence")) rig.convergence = read_size(*v, limits);
  const Camera base = read_rig_base(j, o.path(), limits);
  check_frame_size(base.width, base.height, limits, size_path(j, o.path(), "width"),
                   size_path(j, o.path(), "height"), "stereo camera");
  return expand_stereo(rig, base, prefix);
}

}  // namespace

std::vector<Camera> parse_camera_entry(const json& j, const std::string& path,
                                       const SceneLimits& limits) {
  if (!j.is_object() || !j.contains("rig")) return {parse_camera(j, path, limits)};
  const Node n{&j, path};
  ObjectReader o(n, "a camera rig");
  const Node kind = o.required("rig");
  using Kind = RigKind;
  const Kind k = read_enum<Kind>(
      kind, std::span(kRigKinds));
  std::string prefix = read_string(kind);
  if (auto v = o.optional("name")) prefix = read_camera_name(*v);
  switch (k) {
    case Kind::kOrbit:
      return parse_orbit(o, j, prefix, limits);
    case Kind::kCubemap:
      return parse_cubemap(o, j, prefix, limits);
    case Kind::kStereo:
      break;
  }
  return parse_stereo(o, j, prefix, limits);
}

json camera_to_json(const Camera& c) {
  json j = {{"position", c.position},
            {"projection", c.projection == Projection::kOrthographic ? "orthographic" : "perspective"},
            {"fov_y", c.fov_y_deg},
            {"ortho_height", c.ortho_height},
            {"near", c.near_plane},
            {"far", c.far_plane},
            {"width", c.width},
            {"height", c.height}};
  if (!c.name.empty()) j["name"] = c.name;
  if (c.rotation) {
    j["rotation"] = *c.rotation;
  } else {
    if (c.target) j["target"] = *c.target;
    j["up"] = c.up;
  }
  return j;
}

std::vector<Camera> parse_camera_list(const json& j, const std::string& path,
                                      const SceneLimits& limits) {
  const Node cameras{&j, path};
  const auto items = read_array(cameras, limits.max_cameras, "max_cameras");
  if (items.empty()) {
    fail("invalid_value", cameras.path, "cameras must hold at least one camera, got none");
  }
  std::vector<Camera> out;
  std::set<std::string> names;
  for (const Node& item : items) {
    const std::size_t first = out.size();
    for (Camera& c : parse_camera_entry(item.json(), item.path, limits)) {
      out.push_back(std::move(c));
    }
    if (static_cast<std::int64_t>(out.size()) > limits.max_cameras) {
      fail("limit_exceeded", item.path,
           "the cameras and rigs expand to " + std::to_string(out.size()) +
               " cameras, over the limit max_cameras = " + std::to_string(limits.max_cameras));
    }
    for (std::size_t i = first; i < out.size(); ++i) {
      const std::string& name = out[i].name;
      if (!name.empty() && !names.insert(name).second) {
        fail("duplicate_name", child_path(item.path, "name"),
             "camera name \"" + name + "\" is used by more than one camera");
      }
    }
  }
  return out;
}

// The closed form exists only for densities with a known antiderivative.
void check_method_fits_densities(const Scene& scene) {
  if (scene.render.method != IntegrationMethod::kClosedForm) return;
  for (std::size_t i = 0; i < scene.beams.size(); ++i) {
    if (!has_closed_form(scene.beams[i].density)) {
      fail("invalid_value", "/render/method",
           "closed_form is not available for beam " + std::to_string(i) + "'s density " +
               scene.beams[i].density.name() +
               " (it exists for abe, linear, quadratic and gaussian); use table or march");
    }
  }
}

// The SLIM point sampling knobs (issue 16; docs/slim.md), also listed by
// `hello` (scene_capabilities).
constexpr std::array<std::string_view, 5> kSlimSettingFields{
    "sampling", "depth_threshold", "fill_holes", "cull_backfaces", "evaluation"};

SlimSettings parse_slim_settings(const Node& n) {
  ObjectReader o(n, "slim settings");
  o.allow_only(std::span<const std::string_view>(kSlimSettingFields));
  SlimSettings s;
  // S above 16 leaves 8-pixel gaps that no threshold closes; below 0.25
  // every sphere emits 64 points per pixel it covers.
  if (auto v = o.optional("sampling")) s.sampling = check_closed(*v, read_number(*v), 0.25, 16.0);
  if (auto v = o.optional("depth_threshold")) {
    s.depth_threshold = check_closed(*v, read_number(*v), 0.0, 4.0);
  }
  if (auto v = o.optional("fill_holes")) s.fill_holes = read_bool(*v);
  if (auto v = o.optional("cull_backfaces")) s.cull_backfaces = read_bool(*v);
  if (auto v = o.optional("evaluation")) {
    s.evaluation = read_enum<SlimEvaluation>(
        *v, {{"field", SlimEvaluation::kField},
            {"blend", SlimEvaluation::kBlend},
            {"patch", SlimEvaluation::kPatch}});
  }
  return s;
}

bool scene_reads_files(const json& j) {
  if (!j.is_object()) return false;
  const auto names_file = [](const json& o) { return o.is_object() && o.contains("file"); };
  for (const auto& [key, list] : j.items()) {
    if (!list.is_array()) continue;
    for (const json& entry : list) {
      if (!entry.is_object()) continue;
      if (names_file(entry)) return true;
      for (const auto& [member, value] : entry.items()) {
        if (names_file(value)) return true;
      }
    }
  }
  return false;
}

Scene parse_scene(const json& j, const SceneLoadOptions& opts) {
  const SceneLimits& limits = opts.limits;
  const Node root{&j, ""};
  ObjectReader o(root, "a scene");
  o.allow_only(
      {"version", "background", "light", "lights", "gi", "beams", "occluders", "cameras", "output",
       "render", "slim", "medium", "media", "volumes", "volume"});
  Scene scene;
  if (auto v = o.optional("version")) {
    const std::int64_t version = read_integer(*v);
    if (version != 1) {
      fail("invalid_value", v->path,
           "version must be 1 (the only format version), got " + std::to_string(version));
    }
  }
  if (auto v = o.optional("background")) scene.background = read_color(*v);
  if (auto v = o.optional("light")) scene.light = parse_light(*v);
  if (auto v = o.optional("output")) scene.output = parse_output(*v);
  if (auto v = o.optional("render")) scene.render = parse_render(*v, limits);
  if (auto v = o.optional("slim")) scene.slim = parse_slim_settings(*v);
  if (auto v = o.optional("medium")) scene.medium = parse_medium(*v);
  if (auto v = o.optional("volume")) scene.volume = parse_volume_settings(*v);
  if (auto v = o.optional("media")) {
    std::int64_t mesh_triangles = 0;
    for (const Node& r : read_array(*v, kMaxMediumRegions, "max_medium_regions")) {
      scene.media.push_back(parse_medium_region(r, opts, &mesh_triangles));
    }
  }
  if (auto v = o.optional("lights")) {
    for (const Node& l : read_array(*v, limits.max_lights, "max_lights")) {
      scene.lights.push_back(parse_gi_light(l, limits));
    }
  }
  std::string gi_path = o.path_of("lights");
  if (auto v = o.optional("gi")) {
    scene.gi = parse_gi(*v, limits);
    gi_path = v->path;
  } else {
    scene.gi.photons = std::min(scene.gi.photons, limits.max_photons);
    scene.gi.caustic_photons = std::min(scene.gi.caustic_photons, limits.max_photons - scene.gi.photons);
  }
  scene.gi.max_photon_events = limits.max_photon_events;

  if (auto v = o.optional("beams")) {
    for (const Node& b : read_array(*v, limits.max_beams, "max_beams")) {
      scene.beams.push_back(parse_beam(b, limits));
    }
  }
  add_beam_lights(&scene, o.path_of("beams"));
  check_shadow_budget(scene, limits, gi_path);
  if (auto v = o.optional("occluders")) {
    std::int64_t mesh_triangles = 0, slim_spheres = 0;
    for (const Node& occ : read_array(*v, limits.max_occluders, "max_occluders")) {
      scene.occluders.push_back(parse_occluder(occ, opts, &mesh_triangles, &slim_spheres));
    }
  }

  const Node cameras = o.required("cameras");
  scene.cameras = parse_camera_list(cameras.json(), cameras.path, limits);
  check_supersampled_size(scene.cameras, scene.output.supersample, limits, "/output/supersample");
  check_method_fits_densities(scene);
  // Last: reading volume files is the costliest step, so a scene with a
  // cheaper mistake is refused without it.
  if (auto v = o.optional("volumes")) {
    std::int64_t voxels = 0;
    for (const Node& e : read_array(*v, kMaxVolumes, "max_volumes")) {
      scene.volumes.push_back(parse_volume(e, opts, &voxels));
    }
  }
  return scene;
}

Scene load_scene_file(const std::filesystem::path& file, const SceneLoadOptions& opts) {
  std::error_code ec;
  std::ifstream in;
  if (std::filesystem::is_regular_file(file, ec)) in.open(file, std::ios::binary);
  if (!in.is_open() || !in) {
    throw ProtocolError(ErrorInfo{
        "file_not_found", "scene file " + file.string() + " does not exist or cannot be read", ""});
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    throw ProtocolError(
        ErrorInfo{"file_not_found", "scene file " + file.string() + " could not be read", ""});
  }
  json j;
  try {
    j = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw ProtocolError(ErrorInfo{"bad_json",
                                  "scene file " + file.string() + " is not valid JSON (at byte " +
                                      std::to_string(e.byte) + "): " + e.what(),
                                  ""});
  } catch (const json::out_of_range& e) {
    // nlohmann refuses numbers that overflow a double (e.g. 1e999) while parsing (error 406).
    throw ProtocolError(ErrorInfo{"not_finite",
                                  "scene file " + file.string() +
                                      " contains a number that is not a finite double: " + e.what(),
                                  ""});
  }
  return parse_scene(j, opts);
}

namespace {

template <std::size_t N>
std::vector<std::string_view> names(const std::string_view (&list)[N]) {
  return {std::begin(list), std::end(list)};
}

// Each volume source type's fields besides "type".
json volume_source_fields() {
  json out = json::object();
  for (std::string_view type : volume_source_types()) {
    out[std::string(type)] = type == "raw" ? names(kVolumeRawFields)
                             : type == "marschner_lobb" || type == "heat"
                                 ? names(kVolumeProceduralFields)
                                 : names(kVolumeFileFields);
  }
  return out;
}

}  // namespace

nlohmann::json scene_capabilities() {
  json densities = density_names();
  densities.push_back("table");
  json beam_fields = json::array();
  for (std::string_view f : kBeamFields) beam_fields.push_back(f);
  return {{"beam_types", beam_types()},
          {"beam_fields", beam_fields},
          {"densities", densities},
          {"occluder_types", occluder_types()},
          {"light_types", light_types()},
          {"material_types", {"diffuse", "mirror", "glass"}},
          {"gi_kernels", {"box", "cone", "epanechnikov"}},
          {"gi_direct", {"shadow_maps", "photons"}},
          {"camera_rigs", enum_names(kRigKinds)},
          {"slim_settings",
           std::vector<std::string_view>(kSlimSettingFields.begin(), kSlimSettingFields.end())},
          {"medium_fields", std::vector<std::string_view>(std::begin(kMediumFields),
                                                          std::end(kMediumFields))},
          {"medium_beam_rules", {"gauss2", "midpoint"}},
          {"medium_region_fields", medium_region_fields()},
          {"medium_region_types", medium_region_types()},
          {"volume_fields", names(kVolumeFields)},
          {"volume_source_types", volume_source_types()},
          {"volume_sources", volume_source_fields()},
          {"volume_raw_formats", names(kVolumeRawFormats)},
          {"volume_transfer_fields", names(kVolumeTransferFields)},
          {"volume_transfer_presets", names(kVolumeTransferPresets)},
          {"volume_settings", names(kVolumeSettingFields)},
          {"volume_pyramids", names(kVolumePyramids)},
          {"volume_integrations", names(kVolumeIntegrations)}};
}

}  // namespace beamcast
