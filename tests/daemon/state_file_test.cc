// kinographd's state file: written atomically and read back whole; a corrupt, foreign or
// out-of-range file refused with a message naming the file and what is wrong.
#include "daemon/state_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace kinograph::daemon {
namespace {

class StateFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("kinograph_state_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "rr.state").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& text) { std::ofstream(path_) << text; }
  // The message read_state_file throws for the file, or "" when it reads.
  std::string refusal(const std::string& robot = "rr", const std::string& prefix = "RR") {
    try {
      read_state_file(path_, robot, prefix);
    } catch (const StateFileError& e) {
      return e.what();
    }
    return "";
  }
  static DaemonState sample() {
    DaemonState s;
    s.robot = "rr";
    s.prefix = "RR";
    s.plan_ids_below = 1001;
    messages::ObstacleUpdate ball;
    ball.source = "perception";
    ball.id = "ball";
    ball.shape = collision::Shape::sphere(0.05);
    ball.pose = Eigen::Translation3d(0, 0.1, 1.85) *
                Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
    s.obstacles[{"perception", "ball"}] = ball;
    messages::ObstacleUpdate box = ball;
    box.source = "";
    box.id = "ball";  // the same id from another source is another obstacle
    box.shape = collision::Shape::box(0.1, 0.2, 0.3);
    s.obstacles[{"", "ball"}] = box;
    return s;
  }
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(StateFileTest, WhatIsWrittenIsReadBack) {
  write_state_file(path_, sample());
  EXPECT_FALSE(std::filesystem::exists(path_ + ".tmp"));
  const DaemonState back = read_state_file(path_, "rr", "RR");
  EXPECT_EQ(back.plan_ids_below, 1001);
  ASSERT_EQ(back.obstacles.size(), 2u);
  const auto& ball = back.obstacles.at({"perception", "ball"});
  EXPECT_EQ(ball.source, "perception");
  EXPECT_EQ(ball.id, "ball");
  EXPECT_EQ(ball.shape.kind, collision::ShapeKind::kSphere);
  EXPECT_NEAR(ball.shape.size.x(), 0.05, 1e-15);
  EXPECT_TRUE(ball.pose.isApprox(sample().obstacles.at({"perception", "ball"}).pose, 1e-12));
  EXPECT_EQ(back.obstacles.at({"", "ball"}).shape.kind, collision::ShapeKind::kBox);
  // A second write replaces the first whole.
  DaemonState fewer = sample();
  fewer.obstacles.erase({"", "ball"});
  fewer.plan_ids_below = 2001;
  write_state_file(path_, fewer);
  const DaemonState again = read_state_file(path_, "rr", "RR");
  EXPECT_EQ(again.plan_ids_below, 2001);
  EXPECT_EQ(again.obstacles.size(), 1u);
}

// A mesh obstacle received over LCM keeps its resolved file and scale across a restart.
TEST_F(StateFileTest, AMeshObstacleIsReadBackWithItsFileAndScale) {
  const std::string mesh = (dir_ / "tetra.obj").string();
  std::ofstream(mesh) << "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\n";
  DaemonState s = sample();
  messages::ObstacleUpdate part;
  part.source = "perception";
  part.id = "part";
  part.shape = collision::Shape::mesh(mesh, Eigen::Vector3d(2, 1, 0.5));
  part.pose = Eigen::Isometry3d(Eigen::Translation3d(0.5, 0, 1));
  s.obstacles[{"perception", "part"}] = part;
  write_state_file(path_, s);
  const DaemonState back = read_state_file(path_, "rr", "RR");
  const auto& read = back.obstacles.at({"perception", "part"});
  EXPECT_EQ(read.shape.kind, collision::ShapeKind::kMesh);
  EXPECT_EQ(read.shape.mesh_path, mesh);
  EXPECT_EQ(read.shape.mesh_scale, Eigen::Vector3d(2, 1, 0.5));
  EXPECT_TRUE(read.pose.isApprox(part.pose, 1e-12));
}

TEST_F(StateFileTest, ACorruptFileIsRefusedWithItsNameAndLine) {
  write(
      "{\n \"format\": \"kinographd state\",\n \"version\": 1,\n \"robot\": \"rr\" \"prefix\"\n}");
  const std::string r = refusal();
  EXPECT_NE(r.find("state file '" + path_ + "'"), std::string::npos) << r;
  EXPECT_NE(r.find("line 4"), std::string::npos) << r;
  write("");  // e.g. a file some other program truncated
  EXPECT_NE(refusal().find("is not valid JSON"), std::string::npos) << refusal();
}

TEST_F(StateFileTest, AForeignFileIsRefused) {
  write_state_file(path_, sample());
  EXPECT_NE(refusal("iiwa14", "IIWA").find("belongs to the daemon of robot \"rr\" on prefix RR"),
            std::string::npos)
      << refusal("iiwa14", "IIWA");
  EXPECT_NE(refusal("rr", "RR2").find("on prefix RR, not robot \"rr\" on RR2"), std::string::npos);
  write("{\"name\": \"rr_reach\", \"steps\": 30}");  // some other JSON file
  EXPECT_NE(refusal().find("is not a kinographd state file"), std::string::npos) << refusal();
  write("{\"format\": \"kinographd state\", \"version\": 9}");
  EXPECT_NE(refusal().find("is of version 9; this kinographd reads version 1"), std::string::npos)
      << refusal();
}

TEST_F(StateFileTest, BadFieldsAreRefusedByName) {
  const std::string head =
      "{\"format\": \"kinographd state\", \"version\": 1, \"robot\": \"rr\", \"prefix\": \"RR\", ";
  write(head + "\"plan_ids_below\": -3}");
  EXPECT_NE(refusal().find("plan_ids_below must be a positive integer"), std::string::npos);
  write(head +
        "\"plan_ids_below\": 5, \"obstacles\": [{\"source\": \"\", \"id\": \"huge\", \"shape\": "
        "\"box\", \"size\": [1e80, 1e80, 1e80], \"position\": [0, 0, 0], \"quaternion\": [1, 0, "
        "0, 0]}]}");
  EXPECT_NE(refusal().find("obstacles[0] (\"huge\"): "), std::string::npos) << refusal();
  write(head +
        "\"plan_ids_below\": 5, \"obstacles\": [{\"source\": \"\", \"id\": \"b\", \"shape\": "
        "\"sphere\", \"size\": [0.1, 0, 0], \"position\": [0, 0], \"quaternion\": [1, 0, 0, "
        "0]}]}");
  EXPECT_NE(refusal().find("obstacles[0] (\"b\").position must be an array of 3 numbers"),
            std::string::npos)
      << refusal();
  write(head +
        "\"plan_ids_below\": 5, \"obstacles\": [{\"source\": \"\", \"id\": \"b\", \"shape\": "
        "\"mesh\", \"size\": [0.1, 0, 0], \"position\": [0, 0, 0], \"quaternion\": [1, 0, 0, "
        "0]}]}");
  EXPECT_NE(refusal().find("obstacles[0] (\"b\").mesh missing"), std::string::npos) << refusal();
  write(head +
        "\"plan_ids_below\": 5, \"obstacles\": [{\"source\": \"\", \"id\": \"b\", \"shape\": "
        "\"mesh\", \"size\": [0, 0, 0], \"mesh\": \"" + (dir_ / "gone.obj").string() +
        "\", \"scale\": [1, 1, 1], \"position\": [0, 0, 0], \"quaternion\": [1, 0, 0, 0]}]}");
  EXPECT_NE(refusal().find("obstacles[0] (\"b\").mesh: collision mesh"), std::string::npos)
      << refusal();
  write(head +
        "\"plan_ids_below\": 5, \"obstacles\": [{\"source\": \"\", \"id\": \"b\", \"shape\": "
        "\"torus\", \"size\": [0.1, 0, 0], \"position\": [0, 0, 0], \"quaternion\": [1, 0, 0, "
        "0]}]}");
  EXPECT_NE(refusal().find("is not box, sphere, cylinder, capsule or mesh"), std::string::npos);
  const std::string ball =
      "{\"source\": \"p\", \"id\": \"b\", \"shape\": \"sphere\", \"size\": [0.1, 0, 0], "
      "\"position\": [0, 0, 0], \"quaternion\": [1, 0, 0, 0]}";
  write(head + "\"plan_ids_below\": 5, \"obstacles\": [" + ball + ", " + ball + "]}");
  EXPECT_NE(refusal().find("obstacles[1]: \"b\" of source \"p\" appears twice"), std::string::npos)
      << refusal();
  std::filesystem::remove(path_);
  EXPECT_NE(refusal().find("cannot be opened"), std::string::npos);
}

TEST_F(StateFileTest, AnUnwritableFileIsAnErrorNamingIt) {
  const std::string inside_missing_dir = (dir_ / "no" / "such" / "dir" / "rr.state").string();
  try {
    write_state_file(inside_missing_dir, sample());
    FAIL() << "written";
  } catch (const StateFileError& e) {
    EXPECT_NE(std::string(e.what()).find(inside_missing_dir + ".tmp"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace kinograph::daemon
