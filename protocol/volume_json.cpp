// The scene format's "volumes" and "volume" (docs/scene-format.md,
// "Volumes"): sources, placement, range, transfer functions and the ray
// caster's knobs, validated with the JSON pointer of each bad field.
#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "protocol/json_reader.hpp"
#include "protocol/mesh_obj.hpp"
#include "protocol/scene_json.hpp"
#include "protocol/scene_readers.hpp"
#include "protocol/volume.hpp"
#include "protocol/volume_files.hpp"
#include "protocol/volume_formats/volume_formats.hpp"

namespace beamcast {

using namespace json_read;

namespace {

// "type" and a source type's own fields.
void allow_source_fields(const ObjectReader& s, std::span<const std::string_view> fields) {
  std::vector<std::string_view> allowed{"type"};
  allowed.insert(allowed.end(), fields.begin(), fields.end());
  s.allow_only(allowed);
}

// In (0, hi].
double check_half_open(const Node& n, double v, double hi) {
  if (!(v > 0.0 && v <= hi)) {
    fail("out_of_range", n.path,
         n.name() + " must be in (0, " + format_number(hi) + "], got " + format_number(v));
  }
  return v;
}

std::array<double, 2> read_range(const Node& n) {
  const auto r = read_numbers<2>(n);
  if (!(r[0] < r[1]) || !std::isfinite(r[1] - r[0])) {
    fail("invalid_value", n.path,
         "range must be [lo, hi] with lo < hi (the data values mapped to 0 and 1), got [" +
             format_number(r[0]) + ", " + format_number(r[1]) + "]");
  }
  return r;
}

VolumeFileRef file_ref(const ObjectReader& s, const SceneLoadOptions& opts) {
  const Node file = s.required("file");
  const std::string name = read_string(file);
  if (name.empty()) fail("invalid_value", file.path, "file must be a non-empty relative path");
  return {resolve_asset_path(opts.assets_dir, name, file.path, "volume"), name, file.path,
          opts.assets_dir};
}

// What a source's "type" names: raw, a file format or a procedural field.
struct SourceChoice {
  VolumeSourceType source;
  const VolumeFormat* format;  // null but for a file format
};

std::span<const std::pair<std::string_view, SourceChoice>> source_choices() {
  static const std::vector<std::pair<std::string_view, SourceChoice>> choices = [] {
    std::vector<std::pair<std::string_view, SourceChoice>> c{
        {"raw", {VolumeSourceType::kRaw, nullptr}}};
    for (const VolumeFormat& f : volume_formats()) c.push_back({f.name, {f.source, &f}});
    c.push_back({"marschner_lobb", {VolumeSourceType::kMarschnerLobb, nullptr}});
    c.push_back({"heat", {VolumeSourceType::kHeat, nullptr}});
    return c;
  }();
  return choices;
}

}  // namespace

std::vector<std::string_view> volume_source_types() {
  std::vector<std::string_view> names;
  for (const auto& [name, choice] : source_choices()) names.push_back(name);
  return names;
}

namespace {

// The default range of file data: the whole range of 8- and 16-bit unsigned
// samples, else the data's own (a constant volume maps to 0).
std::array<double, 2> default_range(const VolumeFileData& d, const std::array<double, 2>& data) {
  if (d.type == VolumeSampleType::kU8) return {0.0, 255.0};
  if (d.type == VolumeSampleType::kU16) return {0.0, 65535.0};
  if (data[1] > data[0]) return data;
  return {data[0], data[0] + std::max(1.0, std::abs(data[0]))};
}

// Reads "source" into v's source, grid, range and file; the spacing the
// source implies (procedural: filling [-1, 1]^3; files: the header's or 1).
Vec3 read_source(const Node& n, const SceneLoadOptions& opts, const VoxelBudget& budget,
                 const std::optional<std::array<double, 2>>& range, Volume* v) {
  ObjectReader s(n, "a volume source");
  // "type": raw, a row of the volume-format table, or a procedural field;
  // left out beside "file", the format is found from the file itself.
  SourceChoice choice{VolumeSourceType::kFile, nullptr};  // the format found below
  if (s.optional("type") || !s.optional("file")) {
    choice = read_enum<SourceChoice>(s.required("type"), source_choices());
  }
  v->source = choice.source;
  const VolumeFormat* format = choice.format;
  if (v->source == VolumeSourceType::kMarschnerLobb || v->source == VolumeSourceType::kHeat) {
    allow_source_fields(s, kVolumeProceduralFields);
    // 41^3: the classic Marschner-Lobb sampling; 64^3 for the heat field.
    std::int64_t res = v->source == VolumeSourceType::kMarschnerLobb ? 41 : 64;
    const auto r = s.optional("resolution");
    if (r) res = read_integer(*r);
    const std::string path = r ? r->path : s.path_of("resolution");
    const int n3 =
        check_volume_dims({res, res, res}, budget, "the dimensions", {path, path, path}, path)[0];
    v->range = range.value_or(std::array<double, 2>{0.0, 1.0});
    v->grid = procedural_grid(v->source, n3, v->range);
    const double sp = 2.0 / (n3 - 1);
    return {sp, sp, sp};
  }
  VolumeFileData d;
  VolumeFileRef f;
  if (v->source == VolumeSourceType::kRaw) {
    allow_source_fields(s, kVolumeRawFields);
    const Node dims = s.required("dimensions");
    const std::vector<Node> axes = read_array(dims);
    if (axes.size() != 3) {
      fail("wrong_type", dims.path,
           "dimensions must be an array of 3 integers [nx, ny, nz], got " + describe(dims.json()));
    }
    const std::array<std::int64_t, 3> nd{read_integer(axes[0]), read_integer(axes[1]),
                                         read_integer(axes[2])};
    const auto type =
        read_enum<VolumeSampleType>(s.required("format"), {{"uint8", VolumeSampleType::kU8},
                                                           {"uint16", VolumeSampleType::kU16},
                                                           {"float32", VolumeSampleType::kF32}});
    bool big = false;
    if (auto e = s.optional("endian"))
      big = read_enum<bool>(*e, {{"little", false}, {"big", true}});
    const std::array<int, 3> checked = check_volume_dims(
        nd, budget, "dimensions", {axes[0].path, axes[1].path, axes[2].path}, dims.path);
    f = file_ref(s, opts);
    d = read_raw_volume(f, checked, type, big);
  } else {
    allow_source_fields(s, kVolumeFileFields);
    f = file_ref(s, opts);
    if (!format) format = &detect_volume_format(f);
    v->source = format->source;
    d = read_volume_file(*format, f, budget);
  }
  // Always scanned: a NaN voxel is refused whatever the range.
  const std::array<double, 2> data = volume_data_range(d, f);
  v->range = range ? *range : default_range(d, data);
  v->grid = normalize_volume(d, v->range);
  v->file = f.name;
  return d.spacing.value_or(Vec3{1.0, 1.0, 1.0});
}

TransferFunction read_transfer(const Node& n, const SceneLimits& limits, double default_unit) {
  ObjectReader o(n, "a transfer function");
  o.allow_only(kVolumeTransferFields);
  const auto preset = o.optional("preset");
  const auto points = o.optional("points");
  TransferFunction tf;
  if (preset && points) {
    fail("conflicting_fields", points->path,
         "give a transfer function as a preset or as points, not both");
  }
  if (preset) {
    const std::string name = read_string(*preset);
    const auto p = transfer_preset(name);
    if (!p) {
      std::string names;
      for (std::string_view k : kVolumeTransferPresets) {
        names += (names.empty() ? "\"" : ", \"") + std::string(k) + "\"";
      }
      fail("invalid_value", preset->path,
           "preset must be one of " + names + ", got " + describe(preset->json()));
    }
    tf = *p;
  } else if (points) {
    const std::vector<Node> ps = read_array(*points, kMaxTransferPoints, "max_transfer_points");
    if (ps.size() < 2) {
      fail("invalid_value", points->path,
           "a transfer function needs at least 2 points, got " + std::to_string(ps.size()));
    }
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const Node& p = ps[i];
      if (!p.json().is_array() || p.json().size() != 5) {
        fail("wrong_type", p.path,
             p.name() + " must be [value, r, g, b, opacity], got " + describe(p.json()));
      }
      auto at = [&](std::size_t k) { return Node{&p.json()[k], child_path(p.path, k)}; };
      TransferPoint tp;
      const Node value = at(0);
      tp.value = check_closed(value, read_number(value), 0.0, 1.0);
      for (std::size_t c = 0; c < 3; ++c) {
        tp.color[c] = read_radiometric(at(c + 1));
      }
      tp.opacity = check_closed(at(4), read_number(at(4)), 0.0, 1.0);
      if (i > 0 && !(tp.value > tf.points.back().value)) {
        fail("invalid_value", value.path,
             "transfer points' values must strictly increase: point " + std::to_string(i) +
                 "'s value " + format_number(tp.value) + " is not above point " +
                 std::to_string(i - 1) + "'s " + format_number(tf.points.back().value));
      }
      tf.points.push_back(tp);
    }
  } else {
    fail("missing_field", o.path_of("points"),
         "a transfer function needs a preset or points [[value, r, g, b, opacity], ...]");
  }
  tf.opacity_unit = default_unit;
  if (auto u = o.optional("opacity_unit")) tf.opacity_unit = read_size(*u, limits);
  return tf;
}

}  // namespace

Volume parse_volume(const Node& n, const SceneLoadOptions& opts, std::int64_t* voxels) {
  const SceneLimits& limits = opts.limits;
  ObjectReader o(n, "a volume");
  o.allow_only(kVolumeFields);
  Volume v;
  std::optional<std::array<double, 2>> range;
  if (auto r = o.optional("range")) range = read_range(*r);
  Vec3 spacing = read_source(
      o.required("source"), opts,
      {opts.limits.max_volume_voxels - *voxels, opts.limits.max_volume_voxels}, range, &v);
  *voxels += v.grid->voxels();

  const auto sp = o.optional("spacing");
  if (sp) {
    if (sp->json().is_number()) {
      const double s = read_size(*sp, limits);
      spacing = {s, s, s};
    } else {
      spacing = read_vec3(*sp);
      for (std::size_t a = 0; a < 3; ++a)
        read_size(Node{&sp->json()[a], child_path(sp->path, a)}, limits);
    }
  }
  v.spacing = spacing;
  if (auto r = o.optional("rotation")) v.rotation = read_quaternion(*r);
  Vec3 extent;
  for (int a = 0; a < 3; ++a) extent[a] = (v.grid->dims[a] - 1) * spacing[a];
  const auto origin = o.optional("origin");
  // By default the box is centred on the world's origin, whatever its rotation.
  v.origin = origin ? read_point(*origin, limits) : -1.0 * rotate(v.rotation, 0.5 * extent);
  Vec3 lo, hi;
  v.world_bounds(&lo, &hi);
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(lo[a]) <= limits.max_abs_coordinate &&
          std::abs(hi[a]) <= limits.max_abs_coordinate)) {
      fail("out_of_range",
           sp       ? sp->path
           : origin ? origin->path
                    : n.path,
           "the volume's box reaches beyond max_abs_coordinate = " +
               format_number(limits.max_abs_coordinate));
    }
  }

  // A twentieth of the box's largest side: a preset looks alike on volumes
  // of any size in world units (0.1 for procedural sources' [-1, 1]^3).
  const double unit = *std::max_element(extent.begin(), extent.end()) / 20.0;
  if (auto t = o.optional("transfer")) {
    v.transfer = read_transfer(*t, limits, unit);
  } else {
    v.transfer = *transfer_preset("grey");
    v.transfer.opacity_unit = unit;
  }
  if (auto i = o.optional("intensity")) {
    // Up to 1e6: beyond it any colour saturates a 16-bit frame at opacity 1e-6.
    v.intensity = check_half_open(*i, read_number(*i), 1e6);
  }
  return v;
}

VolumeSettings parse_volume_settings(const Node& n) {
  ObjectReader o(n, "volume settings");
  o.allow_only(kVolumeSettingFields);
  VolumeSettings s;
  // 64 samples per voxel spacing resolve the trilinear field far below a
  // pixel's worth of error, at 32 times the default's cost.
  if (auto v = o.optional("samples_per_voxel")) {
    s.samples_per_voxel = check_half_open(*v, read_number(*v), 64.0);
  }
  if (auto v = o.optional("opacity_correction")) s.opacity_correction = read_bool(*v);
  if (auto v = o.optional("ert")) s.ert_threshold = check_half_open(*v, read_number(*v), 1.0);
  if (auto v = o.optional("jitter")) s.jitter = read_bool(*v);
  if (auto v = o.optional("skip_empty")) s.skip_empty = read_bool(*v);
  if (auto v = o.optional("level")) {
    s.level = static_cast<int>(
        check_closed(*v, static_cast<double>(read_integer(*v)), 0.0, kMaxVolumeLevel));
  }
  if (auto v = o.optional("pyramid")) {
    s.pyramid = read_enum<VolumePyramid>(*v, {{"average", VolumePyramid::kAverage},
                                              {"max", VolumePyramid::kMax},
                                              {"nonzero", VolumePyramid::kNonZero}});
  }
  if (auto v = o.optional("integration")) {
    s.integration =
        read_enum<VolumeIntegration>(*v, {{"point", VolumeIntegration::kPoint},
                                          {"preintegrated", VolumeIntegration::kPreintegrated}});
    if (s.integration == VolumeIntegration::kPreintegrated && !s.opacity_correction) {
      fail("conflicting_fields", v->path,
           "pre-integration needs opacity correction (its table is made for the step's "
           "length): use \"integration\": \"point\" with \"opacity_correction\": false");
    }
  } else if (!s.opacity_correction) {
    s.integration = VolumeIntegration::kPoint;  // the seed's uncorrected samples
  }
  return s;
}

}  // namespace beamcast
