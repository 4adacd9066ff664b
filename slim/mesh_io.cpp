#include "slim/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "protocol/errors.hpp"
#include "protocol/mesh_obj.hpp"

namespace beamcast::slim {

namespace {

[[noreturn]] void fail(const std::string& name, const std::string& where, const std::string& what) {
  throw std::runtime_error(name + (where.empty() ? "" : ":" + where) + ": " + what);
}

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    const std::size_t start = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

bool parse_double(std::string_view t, double* out) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), *out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

bool parse_index(std::string_view t, std::int64_t* out) {
  const auto r = std::from_chars(t.data(), t.data() + t.size(), *out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// Appends the fan (i0, i_k, i_k+1) of a polygon after checking its indices.
void add_polygon(TriangleMesh& mesh, const std::vector<std::int64_t>& idx, const std::string& name,
                 const std::string& where) {
  if (idx.size() < 3)
    fail(name, where, "a face needs at least 3 vertices, got " + std::to_string(idx.size()));
  for (std::int64_t i : idx) {
    if (i < 0 || i >= static_cast<std::int64_t>(mesh.vertices.size())) {
      fail(name, where,
           "vertex index " + std::to_string(i) + " out of range (" +
               std::to_string(mesh.vertices.size()) + " vertices)");
    }
  }
  for (std::size_t k = 1; k + 1 < idx.size(); ++k) {
    mesh.triangles.push_back({static_cast<std::uint32_t>(idx[0]),
                              static_cast<std::uint32_t>(idx[k]),
                              static_cast<std::uint32_t>(idx[k + 1])});
  }
}

void add_vertex(TriangleMesh& mesh, const Vec3& v, const std::string& name,
                const std::string& where) {
  if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
    fail(name, where, "non-finite vertex coordinate");
  }
  mesh.vertices.push_back(v);
}

void check_nonempty(const TriangleMesh& mesh, const std::string& name) {
  if (mesh.triangles.empty()) fail(name, "", "the mesh has no faces");
}

// ---- PLY ----

enum class PlyType { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool ply_type(std::string_view t, PlyType* out) {
  static const std::pair<std::string_view, PlyType> kTypes[] = {
      {"char", PlyType::kI8},    {"int8", PlyType::kI8},     {"uchar", PlyType::kU8},
      {"uint8", PlyType::kU8},   {"short", PlyType::kI16},   {"int16", PlyType::kI16},
      {"ushort", PlyType::kU16}, {"uint16", PlyType::kU16},  {"int", PlyType::kI32},
      {"int32", PlyType::kI32},  {"uint", PlyType::kU32},    {"uint32", PlyType::kU32},
      {"float", PlyType::kF32},  {"float32", PlyType::kF32}, {"double", PlyType::kF64},
      {"float64", PlyType::kF64}};
  for (const auto& [n, ty] : kTypes) {
    if (t == n) {
      *out = ty;
      return true;
    }
  }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::kI8:
    case PlyType::kU8:
      return 1;
    case PlyType::kI16:
    case PlyType::kU16:
      return 2;
    case PlyType::kI32:
    case PlyType::kU32:
    case PlyType::kF32:
      return 4;
    case PlyType::kF64:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kF32;
  bool list = false;
  PlyType count_type = PlyType::kU8;
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> props;
};

// Reads one value of `type` at bytes[*pos] (little-endian host assumed: x86/ARM).
bool read_binary(const std::string& bytes, std::size_t* pos, PlyType type, double* out) {
  const std::size_t n = ply_size(type);
  if (*pos > bytes.size() || bytes.size() - *pos < n) return false;
  const char* p = bytes.data() + *pos;
  *pos += n;
  switch (type) {
    case PlyType::kI8: {
      std::int8_t v;
      std::memcpy(&v, p, 1);
      *out = v;
      break;
    }
    case PlyType::kU8: {
      std::uint8_t v;
      std::memcpy(&v, p, 1);
      *out = v;
      break;
    }
    case PlyType::kI16: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      *out = v;
      break;
    }
    case PlyType::kU16: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      *out = v;
      break;
    }
    case PlyType::kI32: {
      std::int32_t v;
      std::memcpy(&v, p, 4);
      *out = v;
      break;
    }
    case PlyType::kU32: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      *out = v;
      break;
    }
    case PlyType::kF32: {
      float v;
      std::memcpy(&v, p, 4);
      *out = v;
      break;
    }
    case PlyType::kF64: {
      double v;
      std::memcpy(&v, p, 8);
      *out = v;
      break;
    }
  }
  return true;
}

// The ascii body as tokens with their line numbers.
class TokenStream {
 public:
  TokenStream(std::string_view text, int first_line) : text_(text), line_(first_line) {}
  bool next(std::string_view* tok, int* line) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    *tok = text_.substr(start, pos_ - start);
    *line = line_;
    return true;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_;
};

}  // namespace

Aabb TriangleMesh::bounds() const {
  Aabb b;
  for (const Vec3& v : vertices) b.grow(v);
  return b;
}

TriangleMesh read_off(const std::string& text, const std::string& name) {
  // Line-based: the header, the counts, then one vertex or face per line
  // (extra values on a line, colours or normals, are ignored); '#' comments.
  TriangleMesh mesh;
  std::size_t pos = 0;
  int line_no = 0;
  auto next_line = [&](std::vector<std::string_view>* toks) {
    while (pos < text.size()) {
      std::size_t eol = text.find('\n', pos);
      if (eol == std::string::npos) eol = text.size();
      std::string_view line(text.data() + pos, eol - pos);
      pos = eol + 1;
      ++line_no;
      if (const auto hash = line.find('#'); hash != std::string_view::npos)
        line = line.substr(0, hash);
      *toks = split_ws(line);
      if (!toks->empty()) return true;
    }
    return false;
  };
  auto where = [&] { return std::to_string(line_no); };
  std::vector<std::string_view> t;
  if (!next_line(&t)) fail(name, "", "empty file, expected an OFF header");
  const std::string_view head = t[0];
  if (head.size() < 3 || head.substr(head.size() - 3) != "OFF") {
    fail(name, where(), "not an OFF file (first word \"" + std::string(head) + "\")");
  }
  const std::string_view prefix = head.substr(0, head.size() - 3);
  if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos) {
    fail(name, where(), "only 3-D OFF files are supported (header " + std::string(head) + ")");
  }
  if (t.size() > 1 && t[1] == "BINARY") fail(name, where(), "binary OFF is not supported");
  // The counts may follow the keyword on the same line.
  std::vector<std::string_view> counts(t.begin() + 1, t.end());
  if (counts.empty() && !next_line(&counts))
    fail(name, where(), "missing the vertex and face counts");
  std::int64_t nv = 0, nf = 0;
  if (counts.size() < 2 || !parse_index(counts[0], &nv) || !parse_index(counts[1], &nf) || nv < 0 ||
      nf < 0) {
    fail(name, where(), "expected \"vertex_count face_count edge_count\"");
  }
  for (std::int64_t i = 0; i < nv; ++i) {
    if (!next_line(&t)) {
      fail(name, where(),
           "file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    }
    Vec3 v{};
    if (t.size() < 3 || !parse_double(t[0], &v[0]) || !parse_double(t[1], &v[1]) ||
        !parse_double(t[2], &v[2])) {
      fail(name, where(), "vertex " + std::to_string(i) + ": expected three numbers");
    }
    add_vertex(mesh, v, name, where());
  }
  std::vector<std::int64_t> idx;
  for (std::int64_t i = 0; i < nf; ++i) {
    if (!next_line(&t)) {
      fail(name, where(),
           "file ends after " + std::to_string(i) + " of " + std::to_string(nf) + " faces");
    }
    std::int64_t k = 0;
    if (!parse_index(t[0], &k) || k < 0 || static_cast<std::size_t>(k) + 1 > t.size()) {
      fail(name, where(),
           "face " + std::to_string(i) + ": expected a vertex count and that many indices");
    }
    idx.resize(static_cast<std::size_t>(k));
    for (std::int64_t j = 0; j < k; ++j) {
      if (!parse_index(t[static_cast<std::size_t>(j) + 1], &idx[static_cast<std::size_t>(j)])) {
        fail(name, where(),
             "face " + std::to_string(i) + ": index \"" +
                 std::string(t[static_cast<std::size_t>(j) + 1]) + "\" is not an integer");
      }
    }
    add_polygon(mesh, idx, name, where());
  }
  check_nonempty(mesh, name);
  return mesh;
}

TriangleMesh read_obj(const std::string& text, const std::string& name) {
  TriangleMesh mesh;
  try {
    MeshLoadLimits limits;
    limits.max_triangles = std::int64_t{1} << 40;
    limits.max_abs_coordinate = 1e300;
    MeshOccluder m = mesh_from_obj_text(text, name, MeshTransform{}, limits, "");
    mesh.vertices = std::move(m.vertices);
    mesh.triangles = std::move(m.triangles);
  } catch (const ProtocolError& e) {
    throw std::runtime_error(e.info().message);  // already names the file
  }
  return mesh;
}

TriangleMesh read_ply(const std::string& bytes, const std::string& name) {
  // Header: lines up to "end_header".
  std::size_t pos = 0;
  int line_no = 0;
  auto header_line = [&](std::string_view* line) {
    if (pos >= bytes.size()) return false;
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    *line = std::string_view(bytes.data() + pos, eol - pos);
    if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
    pos = eol + 1;
    ++line_no;
    return true;
  };
  auto where = [&] { return std::to_string(line_no); };
  std::string_view line;
  if (!header_line(&line) || line != "ply")
    fail(name, "1", "not a PLY file (no \"ply\" magic line)");
  bool binary = false, have_format = false;
  std::vector<PlyElement> elements;
  for (;;) {
    if (!header_line(&line)) fail(name, where(), "header has no end_header line");
    const auto t = split_ws(line);
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() < 2) fail(name, where(), "format line without a format");
      if (t[1] == "ascii") {
        binary = false;
      } else if (t[1] == "binary_little_endian") {
        binary = true;
      } else {
        fail(name, where(),
             "unsupported PLY format \"" + std::string(t[1]) +
                 "\" (ascii and binary_little_endian are read)");
      }
      have_format = true;
    } else if (t[0] == "element") {
      PlyElement e;
      if (t.size() != 3 || !parse_index(t[2], &e.count) || e.count < 0) {
        fail(name, where(), "expected \"element NAME COUNT\"");
      }
      e.name = t[1];
      elements.push_back(std::move(e));
    } else if (t[0] == "property") {
      if (elements.empty()) fail(name, where(), "property before any element");
      PlyProperty p;
      if (t.size() == 5 && t[1] == "list") {
        p.list = true;
        if (!ply_type(t[2], &p.count_type) || !ply_type(t[3], &p.type)) {
          fail(name, where(), "unknown property type in a list property");
        }
        if (p.count_type == PlyType::kF32 || p.count_type == PlyType::kF64) {
          fail(name, where(), "a list count must have an integer type");
        }
        p.name = t[4];
      } else if (t.size() == 3) {
        if (!ply_type(t[1], &p.type))
          fail(name, where(), "unknown property type \"" + std::string(t[1]) + "\"");
        p.name = t[2];
      } else {
        fail(name, where(), "expected \"property TYPE NAME\" or \"property list TYPE TYPE NAME\"");
      }
      elements.back().props.push_back(std::move(p));
    } else {
      fail(name, where(), "unknown header keyword \"" + std::string(t[0]) + "\"");
    }
  }
  if (!have_format) fail(name, where(), "header has no format line");

  TriangleMesh mesh;
  bool have_vertices = false, have_faces = false;
  // A header without a newline after end_header leaves pos one past the end.
  pos = std::min(pos, bytes.size());
  TokenStream tokens(std::string_view(bytes).substr(pos), line_no + 1);
  std::vector<double> values;
  std::vector<std::int64_t> idx;
  for (const PlyElement& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, ilist = -1;
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const PlyProperty& p = e.props[k];
      if (is_vertex && !p.list && p.name == "x") ix = static_cast<int>(k);
      if (is_vertex && !p.list && p.name == "y") iy = static_cast<int>(k);
      if (is_vertex && !p.list && p.name == "z") iz = static_cast<int>(k);
      if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
        ilist = static_cast<int>(k);
      }
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0)) fail(name, "", "vertex element lacks x, y or z");
    if (is_face && ilist < 0) fail(name, "", "face element lacks a vertex_indices list");
    if (is_face && !have_vertices) fail(name, "", "face element before the vertex element");
    have_vertices |= is_vertex;
    have_faces |= is_face;
    // Nothing to read per instance: a huge count would only spin.
    if (e.props.empty() && e.count > 0) fail(name, "", "element " + e.name + " has no properties");
    for (std::int64_t i = 0; i < e.count; ++i) {
      const std::string here =
          binary ? "element " + e.name + " " + std::to_string(i) : std::string();
      Vec3 v{};
      int tok_line = 0;  // ascii: the line of the last token read
      for (std::size_t k = 0; k < e.props.size(); ++k) {
        const PlyProperty& p = e.props[k];
        auto read_value = [&](PlyType type, double* out) {
          if (binary) {
            if (!read_binary(bytes, &pos, type, out)) {
              fail(name, here, "file ends inside the element (truncated)");
            }
            return;
          }
          std::string_view tok;
          if (!tokens.next(&tok, &tok_line)) {
            fail(name, "", "file ends inside " + e.name + " " + std::to_string(i) + " (truncated)");
          }
          if (!parse_double(tok, out)) {
            fail(name, std::to_string(tok_line),
                 e.name + " " + std::to_string(i) + ": \"" + std::string(tok) +
                     "\" is not a number");
          }
        };
        if (p.list) {
          double n = 0.0;
          read_value(p.count_type, &n);
          if (!(n >= 0.0) || n != std::floor(n) || n > 1e6) {
            fail(name, binary ? here : std::to_string(tok_line), "bad list length");
          }
          values.resize(static_cast<std::size_t>(n));
          for (double& x : values) read_value(p.type, &x);
          if (is_face && static_cast<int>(k) == ilist) {
            idx.clear();
            for (double x : values) {
              // Checked before the cast: a double past int64's range would be UB.
              if (x != std::floor(x) || std::abs(x) > 1e15) {
                fail(name, binary ? here : std::to_string(tok_line),
                     "vertex index " + std::to_string(x) + " is not an index");
              }
              idx.push_back(static_cast<std::int64_t>(x));
            }
            add_polygon(
                mesh, idx, name,
                binary ? here : std::to_string(tok_line) + " (face " + std::to_string(i) + ")");
          }
        } else {
          double x = 0.0;
          read_value(p.type, &x);
          if (static_cast<int>(k) == ix) v[0] = x;
          if (static_cast<int>(k) == iy) v[1] = x;
          if (static_cast<int>(k) == iz) v[2] = x;
        }
      }
      if (is_vertex) {
        add_vertex(mesh, v, name, binary ? here : std::to_string(tok_line));
      }
    }
  }
  if (!have_vertices) fail(name, "", "no vertex element");
  if (!have_faces) fail(name, "", "no face element (a point cloud cannot be fitted)");
  check_nonempty(mesh, name);
  return mesh;
}

TriangleMesh read_mesh(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open the file");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path.string() + ": cannot read the file");
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const std::string name = path.string();
  if (ext == ".off") return read_off(s.str(), name);
  if (ext == ".obj") return read_obj(s.str(), name);
  if (ext == ".ply") return read_ply(s.str(), name);
  throw std::runtime_error(name + ": unknown mesh format \"" + ext + "\" (.off, .obj or .ply)");
}

}  // namespace beamcast::slim
