// The asset-file rules and the streaming OBJ and SLIM readers (issue 43,
// item 5): numbers and indices checked with the file's line, reads that stop
// at the first limit crossed, sizes checked before reading, special files and
// links out of the assets directory refused.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "protocol/asset_files.hpp"
#include "protocol/errors.hpp"
#include "protocol/mesh_obj.hpp"
#include "protocol/slim_io.hpp"

namespace beamcast {
namespace {

namespace fs = std::filesystem;

ErrorInfo obj_error(const std::string& text, MeshLoadLimits limits = {}) {
  try {
    mesh_from_obj_text(text, "t.obj", {}, limits, "/occluders/0/file");
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "accepted: " << text;
  return {};
}

void expect_obj_error(const std::string& text, const std::string& code, const std::string& line,
                      const std::string& words, MeshLoadLimits limits = {}) {
  const ErrorInfo e = obj_error(text, limits);
  EXPECT_EQ(e.code, code) << e.message;
  EXPECT_EQ(e.path, "/occluders/0/file");
  EXPECT_NE(e.message.find("mesh file \"t.obj\", line " + line + ":"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find(words), std::string::npos) << e.message;
}

const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

TEST(ObjReader, IndicesAreRangeCheckedWithoutWrapping) {
  expect_obj_error(kTriangle + "f 1 2 2147483648\n", "bad_mesh", "4",
                   "face index 2147483648 is out of range: 3 vertices");
  EXPECT_EQ(obj_error(kTriangle + "f 1 2 2147483648\n").message.find("-2147483"), std::string::npos);
  expect_obj_error(kTriangle + "f 1 2 99999999999999999999\n", "bad_mesh", "4",
                   "\"99999999999999999999\" is not an integer in range");
  expect_obj_error(kTriangle + "f 1 2 -4\n", "bad_mesh", "4", "face index -4 is out of range");
  expect_obj_error(kTriangle + "f 1 2 0\n", "bad_mesh", "4", "face index 0");
  expect_obj_error(kTriangle + "f 1 2 3x\n", "bad_mesh", "4", "not an integer");
  // A vertex must be defined before a face uses it.
  expect_obj_error("v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", "bad_mesh", "3", "2 vertices are defined");
  expect_obj_error(kTriangle + "f 1 2\n", "bad_mesh", "4", "at least 3 vertices");
  // Negative indices count back; texture and normal parts are skipped.
  const MeshOccluder m =
      mesh_from_obj_text(kTriangle + "vn 0 0 1\nf -3/1/1 -2//1 -1/2\n", "t.obj", {}, {}, "");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
}

TEST(ObjReader, NonFiniteAndMalformedCoordinatesAreRefusedAtTheirLine) {
  expect_obj_error("# a comment\nv nan 0 0\n", "bad_mesh", "2", "\"nan\" is not a finite number");
  expect_obj_error("v 0 0 0\nv 0 -inf 0\n", "bad_mesh", "2", "\"-inf\" is not a finite number");
  expect_obj_error("v 0 0 1e999\n", "bad_mesh", "1", "\"1e999\" is not a finite number");
  expect_obj_error("v 0 0 1.5.2\n", "bad_mesh", "1", "\"1.5.2\" is not a number");
  expect_obj_error("v 0 0\n", "bad_mesh", "1", "needs x, y and z");
  // Underflow is a number (0 or a denormal), and '+' signs are taken.
  const MeshOccluder m = mesh_from_obj_text("v 1e-400 +1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj",
                                            {}, {}, "");
  EXPECT_EQ(m.vertices[0][0], 0.0);
  EXPECT_EQ(m.vertices[0][1], 1.0);
}

TEST(ObjReader, ReadingStopsAtTheFirstLimitCrossed) {
  // Past the limit comes a line that would be an error if it were read.
  MeshLoadLimits limits;
  limits.max_triangles = 5;
  limits.triangles_before = 3;
  expect_obj_error(kTriangle + "f 1 2 3\nf 1 2 3\nf 1 2 3\nf 1 2 nan\n", "limit_exceeded", "6",
                   "max_mesh_triangles = 5", limits);
  // Vertices: at most 3 for each triangle left (2 here: 6 vertices).
  std::string many;
  for (int i = 0; i < 7; ++i) many += "v 0 0 0\n";
  expect_obj_error(many + "v nan 0 0\n", "limit_exceeded", "7", "more than 6 vertices", limits);
}

class AssetDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("beamcast_asset_readers_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  ErrorInfo error_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const ProtocolError& e) {
      return e.info();
    }
    ADD_FAILURE() << "accepted";
    return {};
  }
  fs::path dir_;
};

TEST_F(AssetDir, LinksOutAndSpecialFilesAreRefused) {
  write("in.obj", kTriangle + "f 1 2 3\n");
  fs::create_symlink(dir_ / "in.obj", dir_ / "link_in.obj");
  fs::create_symlink("/etc/passwd", dir_ / "passwd.obj");
  ASSERT_EQ(::mkfifo((dir_ / "fifo.obj").c_str(), 0600), 0);
  fs::create_directories(dir_ / "sub.obj");
  const MeshTransform xf;
  EXPECT_EQ(load_obj_mesh(dir_, "link_in.obj", xf, {}, "/f").triangles.size(), 1u);
  ErrorInfo e = error_of([&] { load_obj_mesh(dir_, "passwd.obj", xf, {}, "/f"); });
  EXPECT_EQ(e.code, "forbidden_path");
  EXPECT_NE(e.message.find("outside the assets directory"), std::string::npos) << e.message;
  for (const char* special : {"fifo.obj", "sub.obj"}) {
    e = error_of([&] { load_obj_mesh(dir_, special, xf, {}, "/f"); });
    EXPECT_EQ(e.code, "forbidden_path") << special;
    EXPECT_NE(e.message.find("is not a regular file"), std::string::npos) << e.message;
  }
  e = error_of([&] { load_obj_mesh(dir_, "none.obj", xf, {}, "/f"); });
  EXPECT_EQ(e.code, "file_not_found");
}

TEST_F(AssetDir, ObjFilesAreSizeCheckedBeforeReadingAndNameTheLine) {
  MeshLoadLimits limits;
  limits.max_triangles = 10;  // 1 MiB + 256 x 10 bytes
  const std::uint64_t cap = kObjBaseBytes + 10 * kObjBytesPerTriangle;
  // One byte over the cap, and an error on line 1 if it were read.
  write("big.obj", "f 0 0 0\n" + std::string(cap + 1 - 8, '#'));
  ErrorInfo e = error_of([&] { load_obj_mesh(dir_, "big.obj", {}, limits, "/f"); });
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_NE(e.message.find(std::to_string(cap + 1) + " bytes, over the " + std::to_string(cap)),
            std::string::npos) << e.message;
  write("nan.obj", "v 0 0 0\n\r\nv 0 nan 0\n");
  e = error_of([&] { load_obj_mesh(dir_, "nan.obj", {}, limits, "/f"); });
  EXPECT_EQ(e.code, "bad_mesh");
  EXPECT_NE(e.message.find("mesh file \"nan.obj\", line 3:"), std::string::npos) << e.message;
  write("long.obj", "v 0 0 0\n" + std::string(kObjMaxLineBytes + 1, ' ') + "\n");
  e = error_of([&] { load_obj_mesh(dir_, "long.obj", {}, limits, "/f"); });
  EXPECT_EQ(e.code, "bad_mesh");
  EXPECT_NE(e.message.find("line 2: longer than"), std::string::npos) << e.message;
}

std::string sphere_json() {
  return R"({"center":[0,0,0],"radius":1,"coefficients":[0,0,0,0,0,0]})";
}

std::string slim_json(int spheres, const std::string& after = "") {
  std::string s = R"({"format":"beamcast-slim","version":1,"spheres":[)";
  for (int i = 0; i < spheres; ++i) s += (i ? "," : "") + sphere_json();
  return s + after + "]}";
}

TEST_F(AssetDir, SlimJsonIsReadUpToTheFirstSphereOverTheLimit) {
  // Four spheres, then a value that is not JSON: it is never reached.
  write("five.json", slim_json(4, ",{\"center\": nope"));
  const SlimCount count{3, 10};  // 3 left of max_slim_spheres = 10
  ErrorInfo e = error_of([&] { load_slim_file(dir_, "five.json", "/f", count, 1e12); });
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/f");
  EXPECT_NE(e.message.find("over the 3 the limit max_slim_spheres = 10 leaves"), std::string::npos)
      << e.message;
  write("three.json", slim_json(3));
  EXPECT_EQ(load_slim_file(dir_, "three.json", "/f", count, 1e12).size(), 3u);
  // A sphere of many values, or a large value beside the spheres, stops the read too.
  std::string fat = R"({"spheres":[{"center":[)";
  for (int i = 0; i < 100; ++i) fat += (i ? ",0" : "0");
  write("fat.json", fat + "]}]}");
  e = error_of([&] { load_slim_file(dir_, "fat.json", "/f", count, 1e12); });
  EXPECT_EQ(e.code, "bad_slim");
  EXPECT_NE(e.message.find("at /spheres/0: has more than 64 JSON values"), std::string::npos)
      << e.message;
  std::string wide = R"({"x":[)";
  for (int i = 0; i < 100; ++i) wide += (i ? ",0" : "0");
  write("wide.json", wide + "],\"spheres\":[" + sphere_json() + "]}");
  e = error_of([&] { load_slim_file(dir_, "wide.json", "/f", count, 1e12); });
  EXPECT_EQ(e.code, "bad_slim");
  EXPECT_NE(e.message.find("has more than 16 JSON values"), std::string::npos) << e.message;
  // The size is checked first: 16 + 1 KiB a sphere left.
  write("big.json", slim_json(1) + std::string(16 + 3 * 1024, ' '));
  e = error_of([&] { load_slim_file(dir_, "big.json", "/f", count, 1e12); });
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_NE(e.message.find("bytes that max_slim_spheres = 10 allows"), std::string::npos)
      << e.message;
}

}  // namespace
}  // namespace beamcast
