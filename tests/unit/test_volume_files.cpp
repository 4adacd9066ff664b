// Volume files through the scene parser (issue 17; protocol/volume_files.hpp):
// raw (uint8, big-endian uint16, float32), NRRD (raw and gzip), INRIA (.inr
// and .inr.gz) written small into a temporary assets directory, the values
// and placement they give, and every malformed file refused with code
// "bad_volume" (or the limit it breaks) at the scene's "file" field.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "protocol/volume.hpp"
#include "tests/unit/volume_test_support.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using test::volume_scene;
using namespace std::string_literals;

constexpr double kTight = 1e-12;  // double arithmetic on values of order 1
const std::string kFile = "/volumes/0/source/file";

json raw(const std::string& file, json dims, const std::string& format) {
  return {{"source",
           {{"type", "raw"}, {"file", file}, {"dimensions", std::move(dims)}, {"format", format}}}};
}

json file_source(const std::string& type, const std::string& file) {
  return {{"source", {{"type", type}, {"file", file}}}};
}

std::uint16_t q_of(double v, double lo, double hi) {
  return static_cast<std::uint16_t>(std::lround((v - lo) / (hi - lo) * 65535.0));
}

// Samples as bytes in the given byte order.
template <class T>
std::string sample_bytes(const std::vector<T>& values, bool big_endian = false) {
  std::string out;
  for (const T& v : values) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
    out.append(b, sizeof(T));
  }
  return out;
}

// An INRIA header: the fields padded with newlines to a multiple of 256 bytes.
std::string inr_header(const std::string& fields) {
  std::string h = "#INRIMAGE-4#{\n" + fields;
  const std::string end = "##}\n";
  const std::size_t total = (h.size() + end.size() + 255) / 256 * 256;
  return h + std::string(total - h.size() - end.size(), '\n') + end;
}

// A temporary assets directory per test (tests run as separate processes).
class VolumeFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("beamcast_volume_" + std::to_string(::getpid()) + "_" +
            std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    opts_.assets_dir = dir_;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  // `plain` as is, then `compressed` as one gzip member (NRRD's attached
  // header before gzip data; all of an .inr.gz with plain empty).
  void write_gz(const std::string& name, const std::string& plain,
                const std::string& compressed) const {
    write(name, plain);
    gzFile gz = gzopen((dir_ / name).c_str(), "ab");
    ASSERT_NE(gz, nullptr);
    ASSERT_EQ(gzwrite(gz, compressed.data(), static_cast<unsigned>(compressed.size())),
              static_cast<int>(compressed.size()));
    gzclose(gz);
  }
  Scene parse(const json& volume) const { return parse_scene(volume_scene(volume), opts_); }
  // The error a volume is refused with: its code and path checked, its
  // message returned for the details.
  std::string refused(const json& volume, const std::string& code,
                      const std::string& path = kFile) const {
    const ErrorInfo e = test::volume_error(volume_scene(volume), opts_);
    EXPECT_EQ(e.code, code) << e.message;
    EXPECT_EQ(e.path, path) << e.message;
    return e.message;
  }
  void expect_message(const json& volume, const std::string& code, const std::string& part) const {
    const std::string m = refused(volume, code);
    EXPECT_NE(m.find(part), std::string::npos) << "\"" << m << "\" lacks \"" << part << "\"";
  }

  std::filesystem::path dir_;
  SceneLoadOptions opts_;
};

TEST_F(VolumeFiles, RawUint8WithDefaults) {
  std::vector<std::uint8_t> v(12);
  for (int i = 0; i < 12; ++i) v[i] = static_cast<std::uint8_t>(20 * i);
  write("a.raw", sample_bytes(v));
  const Scene s = parse(raw("a.raw", {3, 2, 2}, "uint8"));
  const Volume& vol = s.volumes[0];
  EXPECT_EQ(vol.source, VolumeSourceType::kRaw);
  EXPECT_EQ(vol.file, "a.raw");
  EXPECT_EQ(vol.grid->dims, (std::array<int, 3>{3, 2, 2}));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(vol.grid->values[i], 257 * v[i]);  // exact for 8 bits
  EXPECT_EQ(vol.range, (std::array<double, 2>{0, 255}));
  EXPECT_EQ(vol.spacing, (Vec3{1, 1, 1}));
  EXPECT_EQ(vol.origin, (Vec3{-1, -0.5, -0.5}));        // the box centred on 0
  EXPECT_NEAR(vol.transfer.opacity_unit, 0.1, kTight);  // largest side 2 / 20
}

TEST_F(VolumeFiles, RawUint16BigEndian) {
  const std::vector<std::uint16_t> v = {0, 1, 256, 1000, 40000, 65535, 12345, 7};
  write("b.raw", sample_bytes(v, /*big_endian=*/true));
  json j = raw("b.raw", {2, 2, 2}, "uint16");
  j["source"]["endian"] = "big";
  j["spacing"] = {0.5, 1, 2};
  const Scene s = parse(j);
  EXPECT_EQ(s.volumes[0].grid->values, v);  // exact for 16 bits
  EXPECT_EQ(s.volumes[0].range, (std::array<double, 2>{0, 65535}));
  EXPECT_EQ(s.volumes[0].spacing, (Vec3{0.5, 1, 2}));
  // Read as little-endian the bytes swap: 1 reads as 256.
  j["source"]["endian"] = "little";
  EXPECT_EQ(parse(j).volumes[0].grid->values[1], 256);
}

TEST_F(VolumeFiles, RawFloat32RangeDefaultsToTheData) {
  std::vector<float> v;
  for (int i = 0; i < 9; ++i) v.push_back(-2.0f + i);
  for (float f : {1.5f, 2.5f, 3.5f}) v.push_back(f);
  write("c.raw", sample_bytes(v));
  json j = raw("c.raw", {2, 2, 3}, "float32");
  const Scene s = parse(j);
  EXPECT_EQ(s.volumes[0].range, (std::array<double, 2>{-2, 6}));
  for (std::size_t i = 0; i < v.size(); ++i)
    EXPECT_EQ(s.volumes[0].grid->values[i], q_of(v[i], -2, 6));
  j["range"] = {0, 4};  // clamped outside
  const Scene r = parse(j);
  EXPECT_EQ(r.volumes[0].grid->values[0], 0);      // -2
  EXPECT_EQ(r.volumes[0].grid->values[4], 32768);  // 2: round(32767.5)
  EXPECT_EQ(r.volumes[0].grid->values[8], 65535);  // 6
  // A constant volume maps to 0 rather than dividing by a zero range.
  write("d.raw", sample_bytes(std::vector<float>(8, 3.0f)));
  const Scene c = parse(raw("d.raw", {2, 2, 2}, "float32"));
  EXPECT_EQ(c.volumes[0].grid->values, std::vector<std::uint16_t>(8, 0));
  EXPECT_LT(c.volumes[0].range[0], c.volumes[0].range[1]);
}

TEST_F(VolumeFiles, NrrdRawInt16WithSpacings) {
  std::vector<std::int16_t> v(12);
  for (int i = 0; i < 12; ++i) v[i] = static_cast<std::int16_t>(-500 + 100 * i);
  write("e.nrrd",
        "NRRD0004\n# a comment\ntype: short\ndimension: 3\nsizes: 3 2 2\n"
        "spacings: 0.5 1 2\ncontent: test\nkinds: domain domain domain\nmodality:=CT\n"
        "encoding: raw\nendian: little\n\n" +
            sample_bytes(v));
  const Scene s = parse(file_source("nrrd", "e.nrrd"));
  const Volume& vol = s.volumes[0];
  EXPECT_EQ(vol.source, VolumeSourceType::kNrrd);
  EXPECT_EQ(vol.range, (std::array<double, 2>{-500, 600}));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(vol.grid->values[i], q_of(v[i], -500, 600));
  EXPECT_EQ(vol.spacing, (Vec3{0.5, 1, 2}));
  EXPECT_EQ(vol.origin, (Vec3{-0.5, -0.5, -1}));
}

TEST_F(VolumeFiles, NrrdGzipBigEndianFloatWithSpaceDirections) {
  std::vector<float> v(12);
  for (int i = 0; i < 12; ++i) v[i] = 0.5f * i;
  write_gz("f.nrrd",
           "NRRD0005\r\ntype: float\r\ndimension: 3\r\nsizes: 2 3 2\r\n"
           "space: right-anterior-superior\r\n"
           "space directions: (0,0.5,0) (2,0,0) (0,0,1.5)\r\nencoding: gzip\r\nendian: big\r\n\r\n",
           sample_bytes(v, /*big_endian=*/true));
  const Scene s = parse(file_source("nrrd", "f.nrrd"));
  const Volume& vol = s.volumes[0];
  for (int i = 0; i < 12; ++i) EXPECT_EQ(vol.grid->values[i], q_of(v[i], 0, 5.5));
  EXPECT_EQ(vol.grid->dims, (std::array<int, 3>{2, 3, 2}));
  EXPECT_EQ(vol.spacing, (Vec3{0.5, 2, 1.5}));  // the directions' lengths
  json j = file_source("nrrd", "f.nrrd");
  j["spacing"] = 1;  // the scene's spacing wins over the header's
  EXPECT_EQ(parse(j).volumes[0].spacing, (Vec3{1, 1, 1}));
}

TEST_F(VolumeFiles, InrFloatAndSignedFixed) {
  std::vector<float> v(12);
  for (int i = 0; i < 12; ++i) v[i] = static_cast<float>(i * i);
  write("g.inr", inr_header("XDIM=3\nYDIM=2\nZDIM=2\nVDIM=1\nTYPE=float\nPIXSIZE=32 bits\n"
                            "SCALE=2**0\nCPU=decm\nVX=0.25\nVY=0.5\nVZ=1\n#GEOMETRY=CARTESIAN\n") +
                     sample_bytes(v));
  const Scene s = parse(file_source("inr", "g.inr"));
  EXPECT_EQ(s.volumes[0].source, VolumeSourceType::kInr);
  EXPECT_EQ(s.volumes[0].range, (std::array<double, 2>{0, 121}));
  for (int i = 0; i < 12; ++i) EXPECT_EQ(s.volumes[0].grid->values[i], q_of(v[i], 0, 121));
  EXPECT_EQ(s.volumes[0].spacing, (Vec3{0.25, 0.5, 1}));

  const std::vector<std::int16_t> w = {-3, -2, -1, 0, 1, 2, 3, 4};
  write("h.inr",
        inr_header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=signed fixed\nPIXSIZE=16 bits\nCPU=pc\n") +
            sample_bytes(w));
  const Scene t = parse(file_source("inr", "h.inr"));
  EXPECT_EQ(t.volumes[0].range, (std::array<double, 2>{-3, 4}));
  EXPECT_EQ(t.volumes[0].grid->values[3], q_of(0, -3, 4));
  EXPECT_EQ(t.volumes[0].spacing, (Vec3{1, 1, 1}));  // no VX, VY, VZ
}

TEST_F(VolumeFiles, InrGzipBigEndian) {
  const std::vector<std::uint16_t> v = {9, 8, 7, 65535, 5, 4, 3, 0};
  write_gz("i.inr.gz", "",
           inr_header("XDIM=2\nYDIM=2\nZDIM=2\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=16 bits\n"
                      "CPU=sun\nVX=2\nVY=2\nVZ=2\n") +
               sample_bytes(v, /*big_endian=*/true));
  const Scene s = parse(file_source("inr", "i.inr.gz"));
  EXPECT_EQ(s.volumes[0].grid->values, v);
  EXPECT_EQ(s.volumes[0].spacing, (Vec3{2, 2, 2}));
  EXPECT_EQ(s.volumes[0].origin, (Vec3{-1, -1, -1}));
}

TEST_F(VolumeFiles, RawSizeMismatches) {
  write("short.raw", std::string(100, '\1'));
  {
    const std::string m = refused(raw("short.raw", {4, 4, 4}, "uint16"), "bad_volume");
    EXPECT_NE(m.find("need 128 bytes"), std::string::npos) << m;
    EXPECT_NE(m.find("found 100"), std::string::npos) << m;
  }
  write("long.raw", std::string(130, '\1'));
  expect_message(raw("long.raw", {4, 4, 4}, "uint16"), "bad_volume", "found 130");
}

TEST_F(VolumeFiles, NonFiniteVoxelsNamed) {
  std::vector<float> v(8, 1.0f);
  v[5] = std::numeric_limits<float>::quiet_NaN();
  write("nan.raw", sample_bytes(v));
  // Refused whatever the range: the NaN would reach the shader.
  json j = raw("nan.raw", {2, 2, 2}, "float32");
  j["range"] = {0, 1};
  expect_message(j, "bad_volume", "NaN voxel: index 5 (x 1, y 0, z 1)");
  std::vector<double> d(8, 0.0);
  d[6] = -std::numeric_limits<double>::infinity();
  write("inf.nrrd",
        "NRRD0004\ntype: double\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
        "endian: little\n\n" +
            sample_bytes(d));
  expect_message(file_source("nrrd", "inf.nrrd"), "bad_volume",
                 "infinite voxel: index 6 (x 0, y 1, z 1)");
}

TEST_F(VolumeFiles, RawDimensionRefusals) {
  const std::string p = "/volumes/0/source/dimensions";
  refused(raw("x.raw", {4, 4, 1}, "uint8"), "out_of_range", p + "/2");
  refused(raw("x.raw", {4096, 2, 2}, "uint8"), "out_of_range", p + "/0");
  refused(raw("x.raw", {2048, 2048, 2048}, "uint8"), "limit_exceeded", p);
  const std::int64_t huge = 1LL << 40;  // cubed: 2^120
  const std::string m = refused(raw("x.raw", {huge, huge, huge}, "uint8"), "limit_exceeded", p);
  EXPECT_NE(m.find("64-bit"), std::string::npos) << m;
  refused(raw("x.raw", {4, 4}, "uint8"), "wrong_type", p);
  refused(raw("x.raw", {4, 4, 4}, "int32"), "invalid_value", "/volumes/0/source/format");
  json e = raw("x.raw", {4, 4, 4}, "uint8");
  e["source"]["endian"] = "middle";
  refused(e, "invalid_value", "/volumes/0/source/endian");
  e = raw("x.raw", {4, 4, 4}, "uint8");
  e["source"].erase("format");
  refused(e, "missing_field", "/volumes/0/source/format");
}

TEST_F(VolumeFiles, PathsAreConfinedToTheAssets) {
  refused(raw("/etc/passwd", {2, 2, 2}, "uint8"), "forbidden_path");
  refused(raw("../x.raw", {2, 2, 2}, "uint8"), "forbidden_path");
  expect_message(file_source("nrrd", "missing.nrrd"), "file_not_found",
                 "volume file \"missing.nrrd\"");
  refused(file_source("inr", ""), "invalid_value");
  const ErrorInfo e =
      test::volume_error(volume_scene(file_source("inr", "a.inr")), SceneLoadOptions{});
  EXPECT_EQ(e.code, "forbidden_path");  // no assets directory: no files at all
}

TEST_F(VolumeFiles, MalformedNrrd) {
  const std::string head = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\n";
  const std::string data(8, '\2');
  const std::pair<std::string, std::string> cases[] = {
      {"P5\n2 2\n255\n" + data, "is not an NRRD file"},
      {"NRRD0004\ntype: uint8\n", "has no empty line"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nencoding: raw\n\n" + data, "has no \"sizes\""},
      {"NRRD0004\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + data, "has no \"type\""},
      {head + "encoding: raw\nsizes: 2 2\n\n" + data, "a volume has 3"},
      {head + "encoding: raw\nsizes: 2 two 2\n\n" + data, "not integers"},
      {"NRRD0004\ntype: uint8\ndimension: 2\nsizes: 4 2\nencoding: raw\n\n" + data,
       "has dimension"},
      {"NRRD0004\ntype: block\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + data, "has type"},
      {head + "encoding: ascii\n\n2 2 2 2 2 2 2 2", "has encoding \"ascii\""},
      {head + "\n" + data, "has no \"encoding\""},
      {"NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + data + data,
       "has no \"endian\""},
      {head + "encoding: raw\ndata file: other.raw\n\n", "separate data file"},
      {head + "encoding: raw\nbyte skip: -1\n\n" + data, "skipping"},
      {head + "encoding: raw\nthis line has no colon\n\n" + data, "not \"field: value\""},
      {head + "encoding: raw\nspacings: 1 -1 1\n\n" + data, "bad spacing"},
      {head + "encoding: gzip\n\n" + data, "not gzip-compressed"},
      {head + "encoding: raw\n\n" + data.substr(3),
       "after its " + std::to_string(head.size() + 15) + "-byte header, found 5"},
      {head + "encoding: gzip\n\n" + "\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03garbage!"s,
       "corrupt gzip"},
  };
  int n = 0;
  for (const auto& [text, why] : cases) {
    const std::string name = "m" + std::to_string(n++) + ".nrrd";
    write(name, text);
    SCOPED_TRACE(text.substr(0, 80));
    expect_message(file_source("nrrd", name), "bad_volume", why);
  }
  write_gz("short.nrrd", head + "encoding: gzip\n\n", data.substr(1));
  expect_message(file_source("nrrd", "short.nrrd"), "bad_volume", "its gzip data holds 7");
  write_gz("long.nrrd", head + "encoding: gzip\n\n", data + "x");
  expect_message(file_source("nrrd", "long.nrrd"), "bad_volume", "holds more");
  // Sizes break the limits like a raw file's dimensions, reported at "file".
  write("one.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1 8 1\nencoding: raw\n\n" + data);
  refused(file_source("nrrd", "one.nrrd"), "out_of_range");
  write("huge.nrrd",
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 1099511627776 1099511627776 "
        "1099511627776\nencoding: raw\n\n" +
            data);
  expect_message(file_source("nrrd", "huge.nrrd"), "limit_exceeded", "64-bit");
}

TEST_F(VolumeFiles, MalformedInr) {
  const std::string ok = "XDIM=2\nYDIM=2\nZDIM=2\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n";
  const std::string data(8, '\3');
  const std::pair<std::string, std::string> cases[] = {
      {"#INRIMAGE-5#{\n" + std::string(250, '\n') + "##}\n" + data, "not an INRIA image"},
      {"#INRIMAGE-4#{\n" + std::string(64 * 256, '\n'), "has no \"##}\""},
      {"#INRIMAGE-4#{\nXDIM=2\n", "ends inside its header"},
      {inr_header("XDIM=2\nYDIM=2\nZDIM=2\nVDIM=3\nTYPE=float\nPIXSIZE=32 bits\n") + data,
       "VDIM=3"},
      {inr_header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=complex\nPIXSIZE=64 bits\n") + data, "has TYPE"},
      {inr_header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=unsigned fixed\nPIXSIZE=12 bits\n") + data,
       "not supported"},
      {inr_header("XDIM=2\nYDIM=2\nZDIM=2\nTYPE=float\n") + data, "has PIXSIZE"},
      {inr_header("XDIM=2\nYDIM=2\nTYPE=float\nPIXSIZE=32 bits\n") + data,
       "lacks XDIM, YDIM or ZDIM"},
      {inr_header("XDIM=two\n") + data, "not an integer"},
      {inr_header(ok + "CPU=vax\n") + data, "CPU=vax"},
      {inr_header(ok + "VX=0\n") + data, "bad VX"},
      {inr_header(ok + "just words\n") + data, "not KEY=VALUE"},
      {inr_header(ok) + data.substr(1), "is too short"},
  };
  int n = 0;
  for (const auto& [text, why] : cases) {
    const std::string name = "m" + std::to_string(n++) + ".inr";
    write(name, text);
    SCOPED_TRACE(text.substr(0, 80));
    expect_message(file_source("inr", name), "bad_volume", why);
  }
  write_gz("short.inr.gz", "", inr_header(ok) + data.substr(2));
  expect_message(file_source("inr", "short.inr.gz"), "bad_volume", "its gzip data holds 6");
}

TEST_F(VolumeFiles, VoxelsAreSummedOverTheScene) {
  // A sparse file of 2048 x 2048 x 16 zero bytes: exactly max_volume_voxels,
  // so the next volume, however small, is over the limit.
  ASSERT_EQ(2048LL * 2048 * 16, kMaxVolumeVoxels);
  {
    std::ofstream(dir_ / "big.raw", std::ios::binary).close();
    std::filesystem::resize_file(dir_ / "big.raw", static_cast<std::uintmax_t>(kMaxVolumeVoxels));
  }
  json j = volume_scene(raw("big.raw", {2048, 2048, 16}, "uint8"));
  EXPECT_NO_THROW(parse_scene(j, opts_));
  j["volumes"].push_back({{"source", {{"type", "marschner_lobb"}, {"resolution", 2}}}});
  const ErrorInfo e = test::volume_error(j, opts_);
  EXPECT_EQ(e.code, "limit_exceeded");
  EXPECT_EQ(e.path, "/volumes/1/source/resolution");
  EXPECT_NE(e.message.find("other volumes have 67108864"), std::string::npos) << e.message;
}

// skull_2.9.inr and liver.inr.gz from Debian's libcgal-demo, fetched by
// scripts/fetch_cgal_volumes.sh into $BEAMCAST_CGAL_VOLUMES (ctest runs this
// through tests/volume_cgal_data.sh; skipped without them).
TEST(VolumeCgal, SkullAndLiverParse) {
  const char* dir = std::getenv("BEAMCAST_CGAL_VOLUMES");
  if (!dir) GTEST_SKIP() << "BEAMCAST_CGAL_VOLUMES is not set (tests/volume_cgal_data.sh sets it)";
  SceneLoadOptions opts;
  opts.assets_dir = dir;
  json j = volume_scene({{"source", {{"type", "inr"}, {"file", "skull_2.9.inr"}}},
                         {"transfer", {{"preset", "bone"}}}});
  j["volumes"].push_back({{"source", {{"type", "inr"}, {"file", "liver.inr.gz"}}}});
  const Scene s = parse_scene(j, opts);
  const Volume& skull = s.volumes[0];
  EXPECT_EQ(skull.grid->dims, (std::array<int, 3>{64, 64, 64}));
  EXPECT_NEAR(skull.spacing[0], 3.94305, 1e-12);  // the header's VX, VY, VZ
  EXPECT_NEAR(skull.spacing[2], 3.65079, 1e-12);
  // Float data: the range is the data's (0 to about 5.43; the CGAL demo's
  // isovalue 2.9 lies inside), its maximum mapped to 65535.
  EXPECT_GE(skull.range[0], 0.0);
  EXPECT_GT(skull.range[1], 2.9);
  EXPECT_EQ(*std::max_element(skull.grid->values.begin(), skull.grid->values.end()), 65535);
  const Volume& liver = s.volumes[1];
  EXPECT_EQ(liver.grid->dims, (std::array<int, 3>{438, 353, 165}));
  EXPECT_EQ(liver.range, (std::array<double, 2>{0, 255}));
  EXPECT_NEAR(liver.spacing[2], 1.33333, 1e-12);
  // Sparse: most of the liver's box is empty (about 14% of voxels are set).
  const auto set = std::count_if(liver.grid->values.begin(), liver.grid->values.end(),
                                 [](std::uint16_t q) { return q != 0; });
  const double fraction = static_cast<double>(set) / static_cast<double>(liver.grid->voxels());
  EXPECT_GT(fraction, 0.05);
  EXPECT_LT(fraction, 0.5);
}

}  // namespace
}  // namespace beamcast
