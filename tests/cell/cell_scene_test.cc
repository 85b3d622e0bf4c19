// Pictures of several robots: each robot's shapes in its own colour, the robots' trajectories
// on one clock (union of their times, each held at its ends), one path per robot.
#include "render/cell_scene.h"

#include <gtest/gtest.h>

namespace kinograph::render {
namespace {

const std::string kRobots = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/";

TEST(CellSceneTest, EachRobotInItsOwnColour) {
  const dynamics::Model iiwa = dynamics::Model::from_urdf_file(kRobots + "iiwa14/iiwa14.urdf");
  std::vector<dynamics::ComposedRange> ranges;
  const dynamics::Model composite = dynamics::compose(
      {{"a", &iiwa, Eigen::Isometry3d::Identity()}, {"b", &iiwa, Eigen::Isometry3d::Identity()}},
      &ranges);
  const dynamics::Model coloured = colour_robots(composite, ranges);
  ASSERT_EQ(coloured.visual.size(), composite.visual.size());
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    const Eigen::Vector3d hue = robot_colour(static_cast<int>(r)).head<3>().normalized();
    for (int g = ranges[r].visual_offset; g < ranges[r].visual_offset + ranges[r].visual_count;
         ++g) {
      // A shade of the robot's colour: the same direction in RGB, scaled by the URDF's grey.
      EXPECT_TRUE(coloured.visual[g].rgba.head<3>().normalized().isApprox(hue, 1e-12));
    }
  }
  EXPECT_NE(robot_colour(0), robot_colour(1));
  const std::vector<ScenePath> paths = robot_paths(ranges, {"iiwa_link_ee", "iiwa_link_ee"});
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(paths[1].frame, "b/iiwa_link_ee");
  EXPECT_NO_THROW(composite.frame_index(paths[1].frame));
  EXPECT_NE(paths[0].rgba, paths[1].rgba);
}

TEST(CellSceneTest, TrajectoriesOnOneClockHeldAtTheirEnds) {
  const std::vector<dynamics::ComposedRange> ranges = {{"a", 0, 1, 0, 0, 0, 0},
                                                       {"b", 1, 2, 0, 0, 0, 0}};
  Trajectory a{{0.0, 1.0}, {Eigen::VectorXd::Constant(1, 0.0), Eigen::VectorXd::Constant(1, 1.0)}};
  Trajectory b{{0.5, 2.0}, {Eigen::Vector2d(5, 5), Eigen::Vector2d(8, 2)}};
  const Trajectory t = cell_trajectory({a, b}, ranges);
  EXPECT_EQ(t.t, (std::vector<double>{0.0, 0.5, 1.0, 2.0}));
  EXPECT_EQ(t.q[0], Eigen::Vector3d(0, 5, 5));    // b holds its first pose before it starts
  EXPECT_EQ(t.q[1], Eigen::Vector3d(0.5, 5, 5));  // a halfway
  EXPECT_EQ(t.q[3], Eigen::Vector3d(1, 8, 2));    // a holds its last pose after it ends
  EXPECT_THROW(cell_trajectory({a}, ranges), std::invalid_argument);
  Trajectory wrong{{0.0}, {Eigen::VectorXd::Zero(3)}};
  EXPECT_THROW(cell_trajectory({a, wrong}, ranges), std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::render
