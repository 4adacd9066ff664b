// Inputs from fuzzing findings (docs/fuzzing.md) that must keep working. The
// undefined behaviour they once hit shows up under UBSan (the ASan+UBSan stage
// of scripts/test.sh and ctest -L fuzz); here they also check the results.
#include <gtest/gtest.h>

#include "protocol/errors.hpp"
#include "protocol/mesh_obj.hpp"

namespace beamcast {
namespace {

TEST(FuzzRegressions, ObjVertexWeightLinesAreIgnored) {
  // fuzz_obj: tinyobjloader (the earlier reader) converted a huge "vw" joint
  // id to int (UB). The reader skips such lines unread; the mesh is unaffected.
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
      "vw 1 18888888888888888888888 0.45 0 0.45\n"
      "  \tvw 2 -1 0.5\n"
      "f 1 2 3\n"
      "vw 3 1e300 1";  // last line without a newline
  const MeshOccluder m = mesh_from_obj_text(obj, "w.obj", {}, {}, "/occluders/0/file");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.vertices.size(), 3u);
}

TEST(FuzzRegressions, ObjErrorLineNumbersSurviveTheFilter) {
  // Skipped lines still count, so a later error names its line.
  const std::string obj = "v 0 0 0\nvw 1 2 3\nv 1 0 0\nf 1 2 7\n";
  try {
    mesh_from_obj_text(obj, "w.obj", {}, {}, "/occluders/0/file");
    FAIL() << "index 7 of 2 vertices must be refused";
  } catch (const ProtocolError& e) {
    EXPECT_EQ(e.info().code, "bad_mesh");
    EXPECT_NE(e.info().message.find("line 4"), std::string::npos) << e.info().message;
  }
}

}  // namespace
}  // namespace beamcast
