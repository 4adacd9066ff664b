// find_data_dir: binaries find examples/ and bench/ from where the executable
// is (or $BEAMCAST_DATA_DIR), not from a path baked in at build time.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "protocol/data_dir.hpp"

namespace beamcast {
namespace {

namespace fs = std::filesystem;

TEST(DataDir, FoundAboveBuildBin) {
  // This test binary is build/bin/beamcast_unit_tests in the checkout.
  unsetenv("BEAMCAST_DATA_DIR");
  EXPECT_EQ(executable_dir().filename(), "bin");
  const fs::path examples = find_data_dir("examples");
  ASSERT_FALSE(examples.empty());
  EXPECT_TRUE(fs::exists(examples / "paper_10sets.json")) << examples;
  EXPECT_TRUE(fs::exists(find_data_dir("bench") / "plot_accuracy.py"));
  EXPECT_TRUE(find_data_dir("no_such_folder").empty());
}

TEST(DataDir, EnvironmentComesFirst) {
  const fs::path root = fs::temp_directory_path() / "beamcast_data_dir_test";
  fs::create_directories(root / "examples");
  setenv("BEAMCAST_DATA_DIR", root.c_str(), 1);
  const fs::path got = find_data_dir("examples");
  // A root without the folder falls through to the executable's.
  const fs::path bench = find_data_dir("bench");
  unsetenv("BEAMCAST_DATA_DIR");
  EXPECT_EQ(got, fs::weakly_canonical(root / "examples"));
  EXPECT_TRUE(fs::exists(bench / "plot_accuracy.py")) << bench;
  fs::remove_all(root);
}

}  // namespace
}  // namespace beamcast
