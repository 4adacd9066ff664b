#include "protocol/slim_io.hpp"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <limits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "protocol/asset_files.hpp"
#include "protocol/json_reader.hpp"
#include "protocol/scene_readers.hpp"

namespace beamcast {

namespace {

using json_read::fail;
using json_read::Node;
using json_read::ObjectReader;

static_assert(std::endian::native == std::endian::little,
              "the binary SLIM form is read and written as little-endian memory");

constexpr char kMagic[4] = {'B', 'S', 'L', 'M'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kRecordFloats = 20;
constexpr std::size_t kRecordBytes = kRecordFloats * 4 + 4;

SlimPoly read_poly(const Node& n) {
  const auto c = json_read::read_numbers<6>(n);
  return SlimPoly{c};
}

// The local coefficients bound what a height field may be: |A|..|F| such
// that no term overflows a float on the GPU at |u|, |v| <= r.
void check_poly(const SlimPoly& p, const Node& n) {
  for (double c : p.c) {
    if (!(std::abs(c) <= 1e12)) {
      fail("out_of_range", n.path,
           "coefficients must be finite with magnitude <= 1e12, got " + json_read::format_number(c));
    }
  }
}

SlimSphere parse_sphere(const Node& n, double max_abs) {
  ObjectReader o(n, "a SLIM support sphere");
  o.allow_only({"center", "radius", "rotation", "coefficients", "coefficients2", "crease"});
  SlimSphere s;
  SceneLimits limits;
  limits.max_abs_coordinate = max_abs;
  s.center = json_read::read_point(o.required("center"), limits);
  s.radius = json_read::read_size(o.required("radius"), limits);
  if (auto r = o.optional("rotation")) s.rotation = json_read::read_quaternion(*r);
  const Node c = o.required("coefficients");
  s.poly = read_poly(c);
  check_poly(s.poly, c);
  const auto c2 = o.optional("coefficients2");
  const auto crease = o.optional("crease");
  if (c2.has_value() != crease.has_value()) {
    const Node& given = c2 ? *c2 : *crease;
    fail("invalid_value", given.path,
         "\"coefficients2\" and \"crease\" go together: a crease is the min or max of two "
         "polynomials");
  }
  if (c2) {
    s.poly2 = read_poly(*c2);
    check_poly(s.poly2, *c2);
    s.crease = json_read::read_enum<SlimCrease>(*crease, {{"min", SlimCrease::kMin},
                                                          {"max", SlimCrease::kMax}});
  }
  return s;
}

template <class T>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void store(std::string& out, T v) {
  char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  out.append(b, sizeof v);
}

std::string over_limit_message(const std::string& file, const std::string& count,
                               SlimCount limit) {
  return "SLIM file \"" + file + "\" has " + count + " spheres, over the " +
         std::to_string(limit.left) + " the limit max_slim_spheres = " +
         std::to_string(limit.limit) + " leaves for it";
}

std::vector<SlimSphere> parse_binary(const std::string& bytes, const std::string& file,
                                     const std::string& path, SlimCount limit, double max_abs) {
  auto bad = [&](const std::string& why) {
    fail("bad_slim", path, "SLIM file \"" + file + "\" " + why);
  };
  if (bytes.size() < kHeaderBytes) bad("is truncated: shorter than its 16-byte header");
  const auto version = load<std::uint32_t>(bytes.data() + 4);
  if (version != kVersion) {
    bad("has version " + std::to_string(version) + "; this server reads version 1");
  }
  const auto count = load<std::uint32_t>(bytes.data() + 8);
  if (static_cast<std::int64_t>(count) > limit.left) {
    fail("limit_exceeded", path, over_limit_message(file, std::to_string(count), limit));
  }
  const std::size_t want = kHeaderBytes + static_cast<std::size_t>(count) * kRecordBytes;
  if (bytes.size() != want) {
    bad((bytes.size() < want ? "is truncated: " : "has trailing bytes: ") +
        std::to_string(bytes.size()) + " bytes where " + std::to_string(count) + " spheres take " +
        std::to_string(want));
  }
  std::vector<SlimSphere> out(count);
  for (std::size_t i = 0; i < count; ++i) {
    const char* p = bytes.data() + kHeaderBytes + i * kRecordBytes;
    float f[kRecordFloats];
    std::memcpy(f, p, sizeof f);
    const std::string where = "sphere " + std::to_string(i) + " ";
    for (float x : f) {
      if (!std::isfinite(x)) bad(where + "has a value that is not finite");
    }
    SlimSphere& s = out[i];
    s.center = {f[0], f[1], f[2]};
    s.radius = f[3];
    for (double c : s.center) {
      if (std::abs(c) > max_abs) bad(where + "has a centre beyond max_abs_coordinate");
    }
    if (!(s.radius > 0.0) || s.radius > max_abs) bad(where + "has a radius that is not > 0");
    const double qn = std::sqrt(double(f[4]) * f[4] + double(f[5]) * f[5] + double(f[6]) * f[6] +
                                double(f[7]) * f[7]);
    if (!(qn > 1e-6)) bad(where + "has a rotation that cannot be normalized (norm 0)");
    s.rotation = {f[4] / qn, f[5] / qn, f[6] / qn, f[7] / qn};
    for (std::size_t k = 0; k < 6; ++k) {
      s.poly.c[k] = f[8 + k];
      s.poly2.c[k] = f[14 + k];
    }
    const auto crease = load<std::uint32_t>(p + kRecordFloats * 4);
    if (crease > 2) bad(where + "has crease code " + std::to_string(crease) + " (0, 1 or 2)");
    s.crease = static_cast<SlimCrease>(crease);
  }
  return out;
}

// The JSON form read as a stream (nlohmann's callback parser): each element
// of "spheres" is parsed into a SlimSphere when it closes and dropped from the
// document, so what is kept is the spheres, not their JSON. `input` is a
// string or a C stream.
template <class Input>
std::vector<SlimSphere> parse_json_model(Input&& input, const std::string& file,
                                         const std::string& json_path, SlimCount count,
                                         double max_abs) {
  using json = nlohmann::json;
  using Event = json::parse_event_t;
  std::vector<SlimSphere> spheres;
  bool in_spheres = false;  // inside the root's "spheres" array
  std::string key;          // the root member being read
  int values = 0;           // in the current sphere, or outside "spheres"
  const auto too_many = [&](const std::string& where, int limit) {
    fail("bad_slim", where, "has more than " + std::to_string(limit) + " JSON values");
  };
  // Depths (nlohmann's): the root object 0, its members 1, a sphere 2.
  const json::parser_callback_t callback = [&](int depth, Event event, json& parsed) {
    const bool opens = event == Event::object_start || event == Event::array_start;
    if (depth == 1 && event == Event::key) {
      key = parsed.get<std::string>();
    } else if (depth == 1 && event == Event::array_start && key == "spheres") {
      in_spheres = true;
    } else if (depth == 1 && event == Event::array_end && in_spheres) {
      in_spheres = false;
    } else if (in_spheres && depth == 2 && (opens || event == Event::value)) {
      if (static_cast<std::int64_t>(spheres.size()) >= count.left) {
        fail("limit_exceeded", "/spheres",
             over_limit_message(file, "more than " + std::to_string(count.left), count));
      }
      values = 0;
    }
    if (opens || event == Event::value) {
      const bool sphere_part = in_spheres && depth >= 2;
      const int limit = sphere_part ? kSlimMaxSphereValues : kSlimMaxOtherValues;
      if (++values > limit) {
        too_many(sphere_part ? "/spheres/" + std::to_string(spheres.size()) : "/", limit);
      }
    }
    const bool sphere_done = in_spheres && depth == 2 &&
                             (event == Event::object_end || event == Event::array_end ||
                              event == Event::value);
    if (!sphere_done) return true;
    const std::string path = "/spheres/" + std::to_string(spheres.size());
    spheres.push_back(parse_sphere(Node{&parsed, path}, max_abs));
    values = 0;
    return false;  // dropped from the document
  };
  try {
    json root;
    try {
      root = json::parse(std::forward<Input>(input), callback);
    } catch (const json::exception& e) {
      fail("bad_slim", json_path,
           "SLIM file \"" + file +
               "\" is neither the binary form (\"BSLM\") nor valid JSON: " + e.what());
    }
    // Errors inside the file name the field inside it, after the scene's path.
    const Node n{&root, ""};
    ObjectReader o(n, "a SLIM model");
    o.allow_only({"format", "version", "spheres"});
    if (auto f = o.optional("format")) {
      if (json_read::read_string(*f) != "beamcast-slim") {
        fail("invalid_value", f->path, "format must be \"beamcast-slim\"");
      }
    }
    if (auto v = o.optional("version")) {
      if (json_read::read_integer(*v) != 1) fail("invalid_value", v->path, "version must be 1");
    }
    const Node s = o.required("spheres");
    (void)json_read::read_array(s);  // an array (its elements were read above)
    if (spheres.empty()) fail("invalid_value", s.path, "a SLIM surface needs at least one sphere");
  } catch (const ProtocolError& e) {
    if (e.info().path == json_path) throw;  // already about the file as a whole
    const std::string code = e.info().code == "limit_exceeded" ? "limit_exceeded" : "bad_slim";
    const std::string& m = e.info().message;
    fail(code, json_path,
         m.starts_with("SLIM file") ? m
                                    : "SLIM file \"" + file + "\" at " +
                                          (e.info().path.empty() ? "/" : e.info().path) + ": " + m);
  }
  return spheres;
}

}  // namespace

std::vector<SlimSphere> parse_slim_spheres(const nlohmann::json& array, const std::string& path,
                                           SlimCount count, double max_abs_coordinate) {
  const Node n{&array, path};
  const std::vector<Node> items = json_read::read_array(n);
  if (static_cast<std::int64_t>(items.size()) > count.left) {
    fail("limit_exceeded", path,
         "spheres has " + std::to_string(items.size()) + " entries, over the " +
             std::to_string(count.left) + " the limit max_slim_spheres = " +
             std::to_string(count.limit) + " leaves for them");
  }
  std::vector<SlimSphere> out;
  for (const Node& s : items) out.push_back(parse_sphere(s, max_abs_coordinate));
  if (out.empty()) fail("invalid_value", path, "a SLIM surface needs at least one sphere");
  return out;
}

std::vector<SlimSphere> parse_slim_file_bytes(const std::string& bytes, const std::string& file,
                                              const std::string& json_path, SlimCount count,
                                              double max_abs_coordinate) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0) {
    return parse_binary(bytes, file, json_path, count, max_abs_coordinate);
  }
  return parse_json_model(bytes, file, json_path, count, max_abs_coordinate);
}

std::vector<SlimSphere> load_slim_file(const std::filesystem::path& assets_dir,
                                       const std::string& file, const std::string& json_path,
                                       SlimCount count, double max_abs_coordinate) {
  const std::int64_t left = std::max<std::int64_t>(0, count.left);
  const std::int64_t max_bytes =
      left > (std::numeric_limits<std::int64_t>::max() - kSlimFileHeaderBytes) / kSlimMaxJsonBytesPerSphere
          ? std::numeric_limits<std::int64_t>::max()
          : kSlimFileHeaderBytes + kSlimMaxJsonBytesPerSphere * left;
  AssetFile in(assets_dir, file, json_path, "SLIM", static_cast<std::uint64_t>(max_bytes),
               "max_slim_spheres = " + std::to_string(count.limit) + " allows (" +
                   std::to_string(left) + " spheres left, 1 KiB each)");
  char magic[4] = {};
  const bool binary = std::fread(magic, 1, 4, in.stream()) == 4 && std::memcmp(magic, kMagic, 4) == 0;
  std::rewind(in.stream());
  // The binary form's size is exact and checked against its header: read whole.
  if (binary) return parse_binary(in.read_all(), file, json_path, count, max_abs_coordinate);
  return parse_json_model(in.stream(), file, json_path, count, max_abs_coordinate);
}

nlohmann::json slim_to_json(const std::vector<SlimSphere>& spheres) {
  nlohmann::json arr = nlohmann::json::array();
  for (const SlimSphere& s : spheres) {
    nlohmann::json j = {{"center", s.center},
                        {"radius", s.radius},
                        {"rotation", s.rotation},
                        {"coefficients", s.poly.c}};
    if (s.crease != SlimCrease::kNone) {
      j["coefficients2"] = s.poly2.c;
      j["crease"] = std::string(crease_name(s.crease));
    }
    arr.push_back(std::move(j));
  }
  return {{"format", "beamcast-slim"}, {"version", 1}, {"spheres", std::move(arr)}};
}

std::string slim_to_binary(const std::vector<SlimSphere>& spheres) {
  std::string out(kMagic, 4);
  store(out, kVersion);
  store(out, static_cast<std::uint32_t>(spheres.size()));
  store(out, std::uint32_t{0});
  for (const SlimSphere& s : spheres) {
    const double v[kRecordFloats] = {s.center[0],   s.center[1],   s.center[2],   s.radius,
                                     s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3],
                                     s.poly.c[0],   s.poly.c[1],   s.poly.c[2],   s.poly.c[3],
                                     s.poly.c[4],   s.poly.c[5],   s.poly2.c[0],  s.poly2.c[1],
                                     s.poly2.c[2],  s.poly2.c[3],  s.poly2.c[4],  s.poly2.c[5]};
    for (double x : v) store(out, static_cast<float>(x));
    store(out, static_cast<std::uint32_t>(s.crease));
  }
  return out;
}

void write_slim_file(const std::filesystem::path& path, const std::vector<SlimSphere>& spheres) {
  const std::string bytes =
      path.extension() == ".json" ? slim_to_json(spheres).dump(1) + "\n" : slim_to_binary(spheres);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("cannot write SLIM file " + path.string());
}

}  // namespace beamcast
