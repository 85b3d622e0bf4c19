// The data directory lookup (planning/io/data_dir.h): $KINOGRAPH_DATA_DIR first, errors that
// say where they looked, plan-file paths relative to the data directory. The lookup next to an
// installed program is exercised by install_test.sh on a real install.
#include "kinograph/planning/io/data_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "kinograph/planning/io/scene.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;

// Sets $KINOGRAPH_DATA_DIR for one test and restores it after.
class DataDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* v = std::getenv(kDataDirVariable)) saved_ = v;
    root_ = fs::temp_directory_path() / ("kinograph_data_dir_test_" + std::to_string(::getpid()));
    fs::create_directories(root_ / "robots" / "arm");
    std::ofstream(root_ / "robots" / "arm" / "arm.urdf") << "<robot name='arm'/>\n";
  }
  void TearDown() override {
    if (saved_) {
      setenv(kDataDirVariable, saved_->c_str(), 1);
    } else {
      unsetenv(kDataDirVariable);
    }
    fs::remove_all(root_);
  }
  std::optional<std::string> saved_;
  fs::path root_;
};

TEST_F(DataDirTest, TheVariableNamesTheFirstDirectory) {
  setenv(kDataDirVariable, root_.c_str(), 1);
  ASSERT_FALSE(data_dirs().empty());
  EXPECT_EQ(data_dirs().front(), root_);
  const auto found = resolve_scene_path("robots/arm/arm.urdf", "/no/such/anchor");
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, fs::canonical(root_ / "robots/arm/arm.urdf").string());
}

TEST_F(DataDirTest, PathsInsideTheDataDirectoryAreWrittenRelativeToIt) {
  setenv(kDataDirVariable, root_.c_str(), 1);
  EXPECT_EQ(data_relative_path((root_ / "robots/arm/arm.urdf").string()), "robots/arm/arm.urdf");
  // Through a link to robots/, as the build tree's share/kinograph has.
  const fs::path linked = root_.string() + "_linked";
  fs::create_directories(linked);
  fs::create_directory_symlink(root_ / "robots", linked / "robots");
  setenv(kDataDirVariable, linked.c_str(), 1);
  EXPECT_EQ(data_relative_path((root_ / "robots/arm/arm.urdf").string()), "robots/arm/arm.urdf");
  fs::remove_all(linked);
  // Outside every data directory: the absolute path.
  const kinograph::test_support::TempDir outside_dir("kinograph_data_dir_outside");
  const fs::path outside = outside_dir / "outside.urdf";
  std::ofstream(outside) << "x";
  EXPECT_EQ(data_relative_path(outside.string()), fs::canonical(outside).string());
  fs::remove(outside);
}

TEST_F(DataDirTest, AMissingFileSaysWhereItLooked) {
  setenv(kDataDirVariable, "/no/such/kinograph/data", 1);
  EXPECT_TRUE(data_dirs().empty() || data_dirs().front() != "/no/such/kinograph/data");
  EXPECT_NE(describe_data_dirs().find("KINOGRAPH_DATA_DIR=/no/such/kinograph/data (not a "
                                      "directory)"),
            std::string::npos)
      << describe_data_dirs();
  const std::string scene = "robot:\n  urdf: robots/arm/arm.urdf\nhorizon: 1\nsteps: 10\n";
  try {
    parse_scene(scene, (root_ / "elsewhere" / "scene.yaml").string());
    FAIL() << "a scene naming a URDF that is nowhere was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'robot.urdf'"), std::string::npos) << what;
    EXPECT_NE(what.find("file 'robots/arm/arm.urdf' not found"), std::string::npos) << what;
    EXPECT_NE(what.find("KINOGRAPH_DATA_DIR=/no/such/kinograph/data (not a directory)"),
              std::string::npos)
        << what;
  }
  unsetenv(kDataDirVariable);
  EXPECT_NE(describe_data_dirs().find("KINOGRAPH_DATA_DIR (not set)"), std::string::npos);
}

}  // namespace
}  // namespace kinograph::planning
