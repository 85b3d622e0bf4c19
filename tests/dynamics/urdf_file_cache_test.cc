// UrdfFileCache: within its scope each URDF path is read once (a file changed afterwards is not
// read again, an error is given again), outside it every call reads the file.
#include "kinograph/dynamics/urdf_file_cache.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "test_util.h"

namespace kinograph::dynamics {
namespace {

namespace fs = std::filesystem;

class UrdfFileCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/kinograph-urdf-cache-XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    dir_ = dir;
    path_ = (dir_ / "rr.urdf").string();
    fs::copy_file(testing::robot_path("rr/rr.urdf"), path_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void spoil() const { std::ofstream(path_) << "<robot name='x'><link"; }

  fs::path dir_;
  std::string path_;
};

TEST_F(UrdfFileCacheTest, ReadsEachPathOnceWhileInScope) {
  const UrdfFileCache cache;
  const Model first = Model::from_urdf_file(path_);
  spoil();
  const Model second = Model::from_urdf_file(path_);
  EXPECT_EQ(second.nq(), first.nq());
  EXPECT_EQ(second.urdf_path, first.urdf_path);
  EXPECT_EQ(cache.loads(), 1);
  const std::string missing = (dir_ / "missing.urdf").string();
  EXPECT_THROW(Model::from_urdf_file(missing), UrdfError);
  EXPECT_THROW(Model::from_urdf_file(missing), UrdfError);
  EXPECT_EQ(cache.loads(), 2);
}

TEST_F(UrdfFileCacheTest, ReadsTheFileEveryTimeOutsideItsScope) {
  { const UrdfFileCache cache; (void)Model::from_urdf_file(path_); }
  EXPECT_EQ(UrdfFileCache::active(), nullptr);
  spoil();
  EXPECT_THROW(Model::from_urdf_file(path_), UrdfError);
}

}  // namespace
}  // namespace kinograph::dynamics
