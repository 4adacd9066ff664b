// The volume-format table (protocol/volume_formats/volume_formats.hpp): a
// file source without "type" read as its signature, else its extension,
// says; a file in no known format refused at its "file"; a "type" the
// file's signature contradicts refused; hello listing the table's formats.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "protocol/volume.hpp"
#include "protocol/volume_formats/volume_formats.hpp"
#include "tests/unit/volume_test_support.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

const std::string kNrrd = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" +
                          std::string("\0\1\2\3\4\5\6\7", 8);

struct Assets {
  Assets() {
    dir = std::filesystem::temp_directory_path() /
          ("beamcast_vformat_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    opts.assets_dir = dir;
  }
  ~Assets() { std::filesystem::remove_all(dir); }
  void put(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary) << bytes;
  }
  std::filesystem::path dir;
  SceneLoadOptions opts;
};

json untyped(const std::string& file) { return {{"source", {{"file", file}}}}; }

TEST(VolumeFormats, DetectedBySignatureThenExtension) {
  const Assets a;
  a.put("ct.data", kNrrd);  // signature, whatever the name
  {
    gzFile gz = gzopen((a.dir / "brain.bin").c_str(), "wb");
    ASSERT_NE(gz, nullptr);
    std::string inr = "#INRIMAGE-4#{\nXDIM=2\nYDIM=2\nZDIM=2\nTYPE=unsigned fixed\nPIXSIZE=8 bits\n";
    inr += std::string(256 - inr.size() - 4, '\n') + "##}\n" + std::string(8, '\7');
    ASSERT_EQ(gzwrite(gz, inr.data(), static_cast<unsigned>(inr.size())),
              static_cast<int>(inr.size()));
    gzclose(gz);
  }
  json j = test::volume_scene(untyped("ct.data"));
  j["volumes"].push_back(untyped("brain.bin"));  // gzip: the signature of its inflated bytes
  const Scene s = parse_scene(j, a.opts);
  EXPECT_EQ(s.volumes[0].source, VolumeSourceType::kNrrd);
  EXPECT_EQ(s.volumes[0].grid->values[7], 7 * 257);  // uint8 7 of [0, 255]
  EXPECT_EQ(s.volumes[1].source, VolumeSourceType::kInr);
  // No signature: the extension picks the reader, whose own error then shows.
  a.put("bad.NRRD", "not a header");
  const ErrorInfo e = test::volume_error(test::volume_scene(untyped("bad.NRRD")), a.opts);
  EXPECT_EQ(e.code, "bad_volume");
  EXPECT_NE(e.message.find("is not an NRRD file"), std::string::npos) << e.message;
}

TEST(VolumeFormats, UnknownFormatAndContradictedTypeRefused) {
  const Assets a;
  a.put("scan.dcm", "DICM and more");
  const ErrorInfo e = test::volume_error(test::volume_scene(untyped("scan.dcm")), a.opts);
  EXPECT_EQ(e.code, "bad_volume");
  EXPECT_EQ(e.path, "/volumes/0/source/file");
  EXPECT_NE(e.message.find("is in no format read here"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find(".nrrd, .inr, .inr.gz"), std::string::npos) << e.message;
  a.put("ct.inr", kNrrd);
  const ErrorInfo t = test::volume_error(
      test::volume_scene({{"source", {{"type", "inr"}, {"file", "ct.inr"}}}}), a.opts);
  EXPECT_EQ(t.code, "bad_volume");
  EXPECT_EQ(t.path, "/volumes/0/source/file");
  EXPECT_NE(t.message.find("is nrrd (its first bytes say so), not inr"), std::string::npos)
      << t.message;
  // Without "file" the type is still needed.
  const ErrorInfo m = test::volume_error(test::volume_scene({{"source", json::object()}}), a.opts);
  EXPECT_EQ(m.code, "missing_field");
  EXPECT_EQ(m.path, "/volumes/0/source/type");
}

TEST(VolumeFormats, HelloListsEveryRow) {
  const json caps = scene_capabilities();
  for (const VolumeFormat& f : volume_formats()) {
    const std::string name(f.name);
    EXPECT_NE(std::find(caps["volume_source_types"].begin(), caps["volume_source_types"].end(),
                        name),
              caps["volume_source_types"].end())
        << name;
    EXPECT_EQ(caps["volume_sources"][name], json({"file"})) << name;
  }
}

}  // namespace
}  // namespace beamcast
