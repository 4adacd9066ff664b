// MetaImage volumes (protocol/volume_formats/metaimage.hpp): one small int16
// volume written as NRRD and as MetaImage (.mha little- and big-endian and
// zlib-compressed, .mhd with its data file in a subfolder) reads to the same
// voxels, range and spacing; a float pair likewise; every malformed header,
// short data, missing or escaping data file and oversized DimSize refused
// with its code at the scene's "file".
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "protocol/volume.hpp"
#include "tests/unit/volume_test_support.hpp"

namespace beamcast {
namespace {

using nlohmann::json;
using namespace std::string_literals;

const std::string kFile = "/volumes/0/source/file";

// The samples' bytes, in big- or little-endian order.
template <class T>
std::string le_or_be(const std::vector<T>& values, bool big) {
  std::string out(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  if (big == (std::endian::native == std::endian::big)) return out;
  for (auto at = out.begin(); at != out.end(); at += sizeof(T)) std::reverse(at, at + sizeof(T));
  return out;
}

std::string zlib(const std::string& bytes) {
  uLongf n = compressBound(static_cast<uLong>(bytes.size()));
  std::string out(n, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &n,
                      reinterpret_cast<const Bytef*>(bytes.data()),
                      static_cast<uLong>(bytes.size()), 6),
            Z_OK);
  out.resize(n);
  return out;
}

// A 3 x 2 x 2 int16 volume with spacing 0.5, 1.25, 2.
const std::vector<std::int16_t> kShorts = {-300, 0, 7, 1200, -5, 33, 90, 1000, -1000, 2, 4, 8};
const std::string kMetaStart = "ObjectType = Image\nNDims = 3\n";
const std::string kMeta = kMetaStart + "DimSize = 3 2 2\n";
const std::string kShortHead = kMeta + "ElementType = MET_SHORT\nElementSpacing = 0.5 1.25 2\n";

class MetaImage : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = std::filesystem::temp_directory_path() /
            ("beamcast_mha_" + std::to_string(::getpid()));
    std::filesystem::remove_all(root_);
    std::filesystem::create_directories(root_ / "assets" / "sub");
    opts_.assets_dir = root_ / "assets";
  }
  void TearDown() override { std::filesystem::remove_all(root_); }
  void put(const std::string& name, const std::string& bytes) const {
    std::ofstream(opts_.assets_dir / name, std::ios::binary) << bytes;
  }
  static json source(const std::string& file) { return {{"source", {{"file", file}}}}; }
  // The error `header + data` (as "m.mha") is refused with.
  ErrorInfo refusal(const std::string& text) const {
    put("m.mha", text);
    return test::volume_error(test::volume_scene(source("m.mha")), opts_);
  }

  std::filesystem::path root_;
  SceneLoadOptions opts_;
};

TEST_F(MetaImage, ReadsAsTheSameVolumeInNrrd) {
  const std::string le = le_or_be(kShorts, false);
  put("ref.nrrd",
      "NRRD0004\ntype: short\ndimension: 3\nsizes: 3 2 2\nendian: little\nencoding: raw\n"
      "spacings: 0.5 1.25 2\n\n" +
          le);
  put("le.mha", kShortHead + "BinaryData = True\nBinaryDataByteOrderMSB = False\n"
                             "ElementDataFile = LOCAL\n" + le);
  put("be.mha", kShortHead + "ElementByteOrderMSB = True\nElementDataFile = LOCAL\n" +
                    le_or_be(kShorts, true));
  const std::string packed = zlib(le);
  put("z.mha", kShortHead + "CompressedData = True\nCompressedDataSize = " +
                   std::to_string(packed.size()) + "\nElementDataFile = LOCAL\n" + packed);
  put("sub/ct.mhd", kShortHead + "ElementDataFile = ct.raw\n");
  put("sub/ct.raw", le);
  json j = test::volume_scene({{"source", {{"type", "nrrd"}, {"file", "ref.nrrd"}}}});
  j["volumes"].push_back({{"source", {{"type", "metaimage"}, {"file", "le.mha"}}}});
  for (const char* f : {"be.mha", "z.mha", "sub/ct.mhd"}) j["volumes"].push_back(source(f));
  const Scene s = parse_scene(j, opts_);
  ASSERT_EQ(s.volumes.size(), 5u);
  const Volume& ref = s.volumes[0];
  EXPECT_EQ(ref.range, (std::array<double, 2>{-1000, 1200}));
  for (std::size_t i = 1; i < s.volumes.size(); ++i) {
    const Volume& v = s.volumes[i];
    SCOPED_TRACE(v.file);
    EXPECT_EQ(v.source, VolumeSourceType::kFile);
    EXPECT_EQ(v.grid->dims, ref.grid->dims);
    EXPECT_EQ(v.grid->values, ref.grid->values);  // exact: the same samples, the same range
    EXPECT_EQ(v.range, ref.range);
    EXPECT_EQ(v.spacing, ref.spacing);
  }
  EXPECT_EQ(ref.spacing, (Vec3{0.5, 1.25, 2.0}));

  const std::vector<float> floats = {0.25f, -1.5f, 3.0f, 0.0f, 2.0f, 7.5f, 1.0f, -0.5f};
  put("f.nrrd",
      "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nendian: big\nencoding: raw\n\n" +
          le_or_be(floats, true));
  put("f.mha", "NDims = 3\nDimSize = 2 2 2\nElementType = MET_FLOAT\nElementByteOrderMSB = True\n"
               "ElementDataFile = LOCAL\n" + le_or_be(floats, true));
  json k = test::volume_scene(source("f.nrrd"));
  k["volumes"].push_back(source("f.mha"));
  const Scene t = parse_scene(k, opts_);
  EXPECT_EQ(t.volumes[1].grid->values, t.volumes[0].grid->values);
  EXPECT_EQ(t.volumes[1].range, (std::array<double, 2>{-1.5, 7.5}));
  EXPECT_EQ(t.volumes[1].spacing, (Vec3{1.0, 1.0, 1.0}));  // no ElementSpacing
}

TEST_F(MetaImage, MalformedFilesRefused) {
  const std::string data = le_or_be(kShorts, false);
  const std::string local = "ElementDataFile = LOCAL\n";
  const std::string packed = zlib(data);
  const std::pair<std::string, std::string> cases[] = {
      {kShortHead + local + data.substr(2), "header, found 22"},
      {kShortHead + local + data + "x", "is longer than"},
      {kShortHead + "CompressedData = True\n" + local + packed.substr(0, packed.size() / 2),
       "its zlib data holds"},
      {kShortHead + "CompressedData = True\n" + local + "\x78\x9cnot zlib at all"s,
       "corrupt zlib"},
      {kMeta + "DimSize = 3 2\nElementType = MET_SHORT\n" + local + data, "a volume has 3"},
      {kMeta + "DimSize = 3 two 2\nElementType = MET_SHORT\n" + local + data, "not integers"},
      {"NDims = 3\nDimSize = 4 2 2\nElementType = MET_SHORT\n" + local + data, "is too short"},
      {kMeta + "ElementType = MET_LONG_LONG\n" + local + data, "has ElementType MET_LONG_LONG"},
      {kMeta + local + data, "has no ElementType"},
      {"NDims = 2\nDimSize = 6 2\nElementType = MET_SHORT\n" + local + data, "has NDims = 2"},
      {"ObjectType = Transform\n" + local, "a volume is Image"},
      {kShortHead + "BinaryData = False\n" + local + "1 2 3", "only binary data"},
      {kShortHead + "ElementNumberOfChannels = 3\n" + local + data, "one value per voxel"},
      {kShortHead + "HeaderSize = 16\n" + local + data, "skipping is not supported"},
      {kShortHead + "ElementByteOrderMSB = maybe\n" + local + data, "True or False"},
      {kShortHead + "ElementSpacing = 1 0 1\n" + local + data, "bad ElementSpacing"},
      {kShortHead + "no equals sign here\n" + local + data, "not \"Key = Value\""},
      {kShortHead + "Comment = " + std::string(2000, 'x') + "\n" + local, "longer than 1024"},
      {"Comment = a\n" + std::string(200 * 4, '\n'), "first 128 lines"},
      {kShortHead, "ends without an ElementDataFile"},
      {kShortHead + "ElementDataFile = LIST\n", "list or pattern"},
      {kShortHead + "ElementDataFile = slice%03d.raw 0 9 1\n", "list or pattern"},
  };
  for (const auto& [text, why] : cases) {
    SCOPED_TRACE(why);
    const ErrorInfo e = refusal(text);
    EXPECT_EQ(e.code, "bad_volume") << e.message;
    EXPECT_EQ(e.path, kFile);
    EXPECT_NE(e.message.find(why), std::string::npos) << e.message;
  }
}

TEST_F(MetaImage, DataFilesAndSizesChecked) {
  const std::pair<std::string, std::pair<std::string, std::string>> cases[] = {
      {kShortHead + "ElementDataFile = gone.raw\n", {"file_not_found", "\"sub/gone.raw\""}},
      {kShortHead + "ElementDataFile = ../../outside.raw\n", {"forbidden_path", "\"..\""}},
      {kShortHead + "ElementDataFile = /etc/hostname\n", {"forbidden_path", "absolute"}},
      {kMetaStart + "DimSize = 4096 4096 4096\nElementType = MET_UCHAR\n" +
           "ElementDataFile = LOCAL\n",
       {"limit_exceeded", "max_volume_voxels"}},
      {kMetaStart + "DimSize = 1099511627776 1099511627776 1099511627776\n" +
           "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n",
       {"limit_exceeded", "64-bit"}},
      {kMetaStart + "DimSize = 2049 2 2\nElementType = MET_UCHAR\n" +
           "ElementDataFile = LOCAL\n",
       {"out_of_range", "max_volume_dimension"}},
      {kMetaStart + "DimSize = 1 2 2\nElementType = MET_UCHAR\n" +
           "ElementDataFile = LOCAL\n",
       {"out_of_range", "at least 2"}},
  };
  for (const auto& [text, want] : cases) {
    SCOPED_TRACE(text.substr(0, 120));
    put("sub/h.mhd", text);
    const ErrorInfo e = test::volume_error(test::volume_scene(source("sub/h.mhd")), opts_);
    EXPECT_EQ(e.code, want.first) << e.message;
    EXPECT_EQ(e.path, kFile);
    EXPECT_NE(e.message.find(want.second), std::string::npos) << e.message;
  }
}

}  // namespace
}  // namespace beamcast
