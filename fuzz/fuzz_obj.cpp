// libFuzzer target: OBJ text through mesh_from_obj_text (the streaming reader's
// number and index parsing, triangulation, limits and the world transform). A
// mesh that loads has in-range indices and finite, bounded vertices; a refusal
// is a ProtocolError with a serializable message.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "protocol/request.hpp"
#include "protocol/mesh_obj.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  // Byte 0 picks the transform and a small triangle limit (reaches limit_exceeded).
  beamcast::MeshTransform xf;
  if (data[0] & 1) xf.scale = {2.0, -1.0, 0.5};
  if (data[0] & 2) xf.translate = {1e11, 0.0, -3.0};
  if (data[0] & 4) xf.rotation = {0.5, 0.5, 0.5, 0.5};
  beamcast::MeshLoadLimits limits;
  limits.max_triangles = (data[0] & 8) ? 16 : 100000;
  limits.triangles_before = (data[0] & 16) ? 10 : 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const beamcast::MeshOccluder m =
        beamcast::mesh_from_obj_text(text, "fuzz.obj", xf, limits, "/occluders/0/file");
    FUZZ_CHECK(!m.triangles.empty());
    FUZZ_CHECK(limits.triangles_before + static_cast<std::int64_t>(m.triangles.size()) <=
               limits.max_triangles);
    for (const auto& t : m.triangles) {
      for (auto i : t) FUZZ_CHECK(i < m.vertices.size());
    }
    for (const auto& v : m.vertices) {
      for (double c : v) FUZZ_CHECK(std::isfinite(c) && std::abs(c) <= limits.max_abs_coordinate);
    }
  } catch (const beamcast::ProtocolError& e) {
    beamcast::fuzz::check_error(e.info());
    beamcast::fuzz::serialize(beamcast::error_response(1, e.info()));
  }
  return 0;
}
