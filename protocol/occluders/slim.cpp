#include "protocol/occluders/slim.hpp"

#include <algorithm>
#include <functional>
#include <string>
#include <string_view>

#include "protocol/check.hpp"
#include "protocol/scene.hpp"
#include "protocol/occluders/occluder_parse.hpp"
#include "protocol/slim_io.hpp"

namespace beamcast {

using namespace json_read;

SlimSurface::SlimSurface(std::vector<SlimSphere> s)
    : spheres(std::move(s)), box(slim_bounds(spheres)), field(&spheres) {}

const std::vector<std::array<double, 2>>& SlimSurface::height_ranges() const {
  std::call_once(ranges_once_, [this] {
    ranges_.resize(spheres.size());
    for (std::size_t i = 0; i < spheres.size(); ++i) ranges_[i] = slim_height_range(spheres[i]);
  });
  return ranges_;
}

const std::string& SlimSurface::content_key() const {
  std::call_once(key_once_, [this] {
    // The fields one by one (a SlimSphere's padding is not its value).
    std::string bytes;
    auto put = [&bytes](const auto& v) {
      bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
    };
    for (const SlimSphere& s : spheres) {
      put(s.center);
      put(s.radius);
      put(s.rotation);
      put(s.poly.c);
      put(s.poly2.c);
      put(static_cast<int>(s.crease));
    }
    const std::hash<std::string_view> hash;
    const std::string_view all(bytes);
    const std::string_view half = all.substr(all.size() / 2);
    key_ = "spheres:" + std::to_string(spheres.size()) + ":" + std::to_string(hash(all)) + ":" +
           std::to_string(hash(half));
  });
  return key_;
}

SlimOccluder SlimOccluder::from_spheres(std::vector<SlimSphere> spheres) {
  SlimOccluder o;
  o.surface = std::make_shared<const SlimSurface>(std::move(spheres));
  return o;
}

SlimOccluder SlimOccluder::parse(const OccluderParse& in) {
  in.allow({"spheres", "file", "translate", "scale", "rotation"});
  const SceneLimits& limits = in.limits();
  const SlimCount count{limits.max_slim_spheres - *in.slim_spheres, limits.max_slim_spheres};
  const auto inline_spheres = in.fields.optional("spheres");
  const auto file = in.fields.optional("file");
  if (inline_spheres.has_value() == file.has_value()) {
    fail(inline_spheres ? "invalid_value" : "missing_field", in.fields.path_of("spheres"),
         "a slim occluder takes its spheres inline (\"spheres\") or from a model file "
         "(\"file\"), exactly one of the two");
  }
  std::vector<SlimSphere> spheres;
  std::string name;
  if (inline_spheres) {
    spheres = parse_slim_spheres(inline_spheres->json(), inline_spheres->path, count,
                                 limits.max_abs_coordinate);
  } else {
    name = read_string(*file);
    if (name.empty()) fail("invalid_value", file->path, "file must be a non-empty relative path");
    spheres = load_slim_file(in.opts.assets_dir, name, file->path, count,
                             limits.max_abs_coordinate);
  }
  BEAMCAST_CHECK(static_cast<std::int64_t>(spheres.size()) <= count.left,
                 "the SLIM readers stop at the spheres left");
  *in.slim_spheres += static_cast<std::int64_t>(spheres.size());

  Vec3 translate{0.0, 0.0, 0.0};
  double scale = 1.0;
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};
  if (auto t = in.fields.optional("translate")) translate = read_point(*t, limits);
  if (auto s = in.fields.optional("scale")) scale = read_size(*s, limits);
  if (auto r = in.fields.optional("rotation")) rotation = read_quaternion(*r);
  transform_slim(spheres, translate, scale, rotation);
  const Node& where = inline_spheres ? *inline_spheres : *file;
  for (const SlimSphere& s : spheres) {
    for (double c : s.center) {
      if (!(std::abs(c) <= limits.max_abs_coordinate) ||
          !(s.radius <= limits.max_abs_coordinate)) {
        fail("out_of_range", where.path,
             "a sphere placed by translate/scale lies beyond max_abs_coordinate");
      }
    }
  }
  SlimOccluder out = from_spheres(std::move(spheres));
  out.file = name;
  return out;
}

bool has_slim(const Scene& scene) {
  return std::any_of(scene.occluders.begin(), scene.occluders.end(), [](const Occluder& o) {
    return std::holds_alternative<SlimOccluder>(o.shape);
  });
}

std::optional<OccluderHit> SlimOccluder::intersect(const Vec3& o, const Vec3& v, double t_min,
                                                   double t_max) const {
  const auto h = surface->field.intersect(o, v, t_min, t_max);
  if (!h) return std::nullopt;
  return OccluderHit{h->t, h->n};
}

}  // namespace beamcast
