// Pixel tests of the renderer: the robot appears where forward kinematics puts it, obstacles
// appear, the background is where nothing is, pictures have the asked size and frame count,
// real third-party meshes (Barrett WAM from dart-doc) render, and bad input fails clearly.
#include "render/scene_renderer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "tests/render/test_scenes.h"

namespace kinograph::render {
namespace {

using test::count_near;
using test::is_blue;
using test::is_red;

// One GL context for the whole binary: creating contexts is cheap, but the first draw JIT-
// compiles shaders, which every test would pay again.
SceneRenderer& shared_renderer() {
  static SceneRenderer renderer;
  return renderer;
}

class RedArm : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ =
        std::make_unique<dynamics::Model>(dynamics::Model::from_urdf_string(test::red_arm_urdf()));
    Eigen::VectorXd q0(3), q1(3);
    q0 << -0.8, 0.3, 0.9;
    q1 << 0.9, -0.6, 1.3;
    scene_.model = model_.get();
    scene_.trajectory = test::smooth_trajectory(q0, q1);
    SceneObstacle box;
    box.obstacle.shape = collision::Shape::box(0.3, 0.3, 0.3);
    box.obstacle.pose.translation() = Eigen::Vector3d(0.0, -0.9, 0.15);
    box.rgba = Eigen::Vector4d(0.2, 0.4, 0.9, 1.0);
    scene_.obstacles.push_back(box);
  }

  // Midpoints of the three red links at configuration q (on each cylinder's axis, which
  // the cylinder's near surface covers in any view).
  std::vector<Eigen::Vector3d> link_midpoints(const Eigen::VectorXd& q) const {
    dynamics::Data data(*model_);
    dynamics::forward_kinematics(*model_, data, q);
    std::vector<Eigen::Vector3d> points;
    for (const dynamics::Geometry& g : model_->visual) {
      if (g.body >= 0) points.push_back((data.body_pose[g.body] * g.origin).translation());
    }
    return points;
  }

  // A blue ball in front of the arm, moving from kBallFrom to kBallTo over the plan's 2 s.
  static SceneObstacle moving_ball() {
    SceneObstacle ball;
    ball.obstacle.shape = collision::Shape::sphere(0.12);
    ball.obstacle.trajectory =
        collision::PoseTrajectory({0.0, 2.0}, {Eigen::Isometry3d(Eigen::Translation3d(kBallFrom)),
                                               Eigen::Isometry3d(Eigen::Translation3d(kBallTo))});
    ball.rgba = Eigen::Vector4d(0.2, 0.4, 0.9, 1.0);
    return ball;
  }
  inline static const Eigen::Vector3d kBallFrom{-0.7, -0.9, 0.2};
  inline static const Eigen::Vector3d kBallTo{0.7, -0.9, 0.2};

  std::unique_ptr<dynamics::Model> model_;
  RenderScene scene_;
};

TEST_F(RedArm, StripHasAskedSizeAndFrameCount) {
  FrameOptions options;
  options.frames = 4;
  options.width = 800;
  options.height = 300;
  const RenderResult result = shared_renderer().strip(scene_, options);
  EXPECT_EQ(result.image.width, 800);
  EXPECT_EQ(result.image.height, 300);
  ASSERT_EQ(result.panels.size(), 4u);
  ASSERT_EQ(result.times.size(), 4u);
  EXPECT_DOUBLE_EQ(result.times.front(), 0.0);
  EXPECT_DOUBLE_EQ(result.times.back(), 2.0);
  int covered = 0;
  for (const Panel& p : result.panels) {
    EXPECT_EQ(p.x, covered);
    covered += p.width;
  }
  EXPECT_EQ(covered, 800);
}

TEST_F(RedArm, RobotPixelsAreWhereForwardKinematicsPutsThem) {
  FrameOptions options;
  options.frames = 3;
  options.width = 960;
  options.height = 360;
  const RenderResult result = shared_renderer().strip(scene_, options);
  for (const Panel& panel : result.panels) {
    const auto points = link_midpoints(scene_.trajectory.at(panel.time));
    ASSERT_EQ(points.size(), 3u);
    for (const Eigen::Vector3d& p : points) {
      const auto pixel = panel.project(p);
      ASSERT_TRUE(pixel.has_value());
      ASSERT_GE(pixel->x(), panel.x);
      ASSERT_LT(pixel->x(), panel.x + panel.width);
      EXPECT_GE(count_near(result.image, *pixel, 1, is_red), 5)
          << "no arm colour at t = " << panel.time << " near pixel " << pixel->transpose();
    }
  }
  // The first pose's elbow region is not red in the last panel: frames really differ.
  const Panel& last = result.panels.back();
  const auto first_points = link_midpoints(scene_.trajectory.q.front());
  const auto last_points = link_midpoints(scene_.trajectory.q.back());
  const auto moved = last.project(first_points[2]);
  ASSERT_TRUE(moved.has_value());
  ASSERT_GT((first_points[2] - last_points[2]).norm(), 0.3);
  EXPECT_EQ(count_near(result.image, *moved, 1, is_red), 0);
}

TEST_F(RedArm, ObstacleColourAppearsAtItsProjection) {
  FrameOptions options;
  options.frames = 2;
  options.width = 800;
  options.height = 400;
  const RenderResult result = shared_renderer().strip(scene_, options);
  for (const Panel& panel : result.panels) {
    // The box's top face centre faces the camera, which looks from above.
    const auto pixel = panel.project(Eigen::Vector3d(0.0, -0.9, 0.3));
    ASSERT_TRUE(pixel.has_value());
    EXPECT_GE(count_near(result.image, *pixel, 2, is_blue), 20);
  }
}

TEST_F(RedArm, BackgroundWhereNothingIs) {
  FrameOptions options;
  options.frames = 2;
  options.width = 600;
  options.height = 300;
  options.floor = false;
  options.labels = false;
  options.background = Eigen::Vector4f(1.f, 1.f, 1.f, 1.f);
  const RenderResult result = shared_renderer().strip(scene_, options);
  // Corners of each panel are far from the framed motion.
  for (const Panel& panel : result.panels) {
    for (const auto& [x, y] : {std::pair{panel.x + 2, 2},
                               {panel.x + panel.width - 3, 2},
                               {panel.x + 2, panel.height - 3},
                               {panel.x + panel.width - 3, panel.height - 3}}) {
      const std::uint8_t* p = result.image.at(x, y);
      EXPECT_EQ(p[0], 255) << x << "," << y;
      EXPECT_EQ(p[1], 255);
      EXPECT_EQ(p[2], 255);
    }
  }
  // And something was drawn at all: not every pixel is background.
  int drawn = 0;
  for (std::size_t i = 0; i < result.image.rgba.size(); i += 4) {
    if (result.image.rgba[i] != 255 || result.image.rgba[i + 1] != 255) ++drawn;
  }
  EXPECT_GT(drawn, 1000);
}

TEST_F(RedArm, AutoCameraSeesTheWholeMotion) {
  const double aspect = 1.5;
  const Camera camera = shared_renderer().auto_camera(scene_, aspect);
  for (const Eigen::Vector3d& p : shared_renderer().motion_points(scene_)) {
    const auto pixel = camera.project(p, 300, 200);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_GE(pixel->x(), -1e-6);
    EXPECT_LE(pixel->x(), 300 + 1e-6);
    EXPECT_GE(pixel->y(), -1e-6);
    EXPECT_LE(pixel->y(), 200 + 1e-6);
  }
}

TEST_F(RedArm, GhostOverlayShowsFinalPoseAndPath) {
  FrameOptions options;
  options.frames = 5;
  options.width = 700;
  options.height = 500;
  options.path_color = Eigen::Vector4f(0.1f, 0.8f, 0.1f, 1.f);  // green: unlike arm and box
  const RenderResult result = shared_renderer().ghost(scene_, options);
  EXPECT_EQ(result.image.width, 700);
  EXPECT_EQ(result.image.height, 500);
  ASSERT_EQ(result.panels.size(), 1u);
  EXPECT_EQ(result.times.size(), 5u);
  const Panel& panel = result.panels.front();
  for (const Eigen::Vector3d& p : link_midpoints(scene_.trajectory.q.back())) {
    const auto pixel = panel.project(p);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_GE(count_near(result.image, *pixel, 1, is_red), 5);
  }
  // The end-effector path: green pixels near the tip's projection at the start (where the
  // faintest ghost is drawn) and in the middle of the motion.
  const auto is_green = [](const std::uint8_t* p) { return p[1] > p[0] + 40 && p[1] > p[2] + 40; };
  dynamics::Data data(*model_);
  const int tip = model_->frame_index("tip");
  int near_path = 0;
  for (double t : {0.0, 0.5, 1.0, 1.5}) {
    dynamics::forward_kinematics(*model_, data, scene_.trajectory.at(t));
    const auto pixel = panel.project(dynamics::frame_pose(*model_, data, tip).translation());
    ASSERT_TRUE(pixel.has_value());
    if (count_near(result.image, *pixel, 2, is_green) > 0) ++near_path;
  }
  EXPECT_GE(near_path, 3);
}

// A ball that moves from the arm's left to its right: each strip panel shows it where it is at
// that panel's time, and no longer where it was.
TEST_F(RedArm, MovingObstacleIsDrawnWhereItIsAtEachFrame) {
  const Eigen::Vector3d from = kBallFrom, to = kBallTo;
  scene_.obstacles = {moving_ball()};
  FrameOptions options;
  options.frames = 3;
  options.width = 960;
  options.height = 360;
  const RenderResult result = shared_renderer().strip(scene_, options);
  ASSERT_EQ(result.panels.size(), 3u);
  for (const Panel& panel : result.panels) {
    const Eigen::Vector3d centre = from + (to - from) * panel.time / 2.0;
    const auto pixel = panel.project(centre);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_GE(count_near(result.image, *pixel, 2, is_blue), 20) << "t = " << panel.time;
  }
  const Panel &first = result.panels.front(), &last = result.panels.back();
  const auto start = first.project(from), end = last.project(to);
  ASSERT_TRUE(start && end);
  // Its image moved within the panel by far more than its size ...
  EXPECT_GT(((*end - Eigen::Vector2d(last.x, 0)) - (*start - Eigen::Vector2d(first.x, 0))).norm(),
            100.0);
  // ... and where it started there is no ball at the end.
  EXPECT_EQ(count_near(result.image, *last.project(from), 2, is_blue), 0);
  EXPECT_EQ(count_near(result.image, *first.project(to), 2, is_blue), 0);
}

// In a ghost overlay a moving obstacle is solid where it is at the end and faded where it was
// at the first pose.
TEST_F(RedArm, GhostOverlayFadesAMovingObstacleAlongItsWay) {
  const Eigen::Vector3d from = kBallFrom, to = kBallTo;
  scene_.obstacles = {moving_ball()};
  FrameOptions options;
  options.frames = 3;
  options.width = 700;
  options.height = 500;
  options.floor = false;
  const RenderResult result = shared_renderer().ghost(scene_, options);
  const Panel& panel = result.panels.front();
  EXPECT_GE(count_near(result.image, *panel.project(to), 2, is_blue), 20);
  // The first ghost (opacity 0.18 over white): bluish, but far from the solid colour.
  const auto faded_blue = [](const std::uint8_t* p) {
    return p[2] > p[0] + 12 && p[0] > 150 && p[2] > 200;
  };
  EXPECT_GE(count_near(result.image, *panel.project(from), 2, faded_blue), 20);
  EXPECT_EQ(count_near(result.image, *panel.project(from), 2, is_blue), 0);
}

// The replanning figure: the first plan as grey ghosts with a green path, the second in the
// arm's red with its own (yellow) path, and an obstacle only the second plan has in magenta.
TEST_F(RedArm, CompareShowsBothPathsAndTheChangedObstacle) {
  RenderScene after = scene_;
  Eigen::VectorXd q0(3), q2(3);
  q0 << -0.8, 0.3, 0.9;
  q2 << 0.9, 0.5, 0.4;
  after.trajectory = test::smooth_trajectory(q0, q2);
  SceneObstacle added;
  added.name = "added";
  added.obstacle.shape = collision::Shape::box(0.25, 0.25, 0.25);
  added.obstacle.pose.translation() = Eigen::Vector3d(0.9, 0.6, 0.125);
  after.obstacles.push_back(added);
  CompareOptions options;
  options.frame.frames = 4;
  options.frame.width = 800;
  options.frame.height = 600;
  options.frame.path_color = Eigen::Vector4f(0.95f, 0.85f, 0.1f, 1.f);
  const RenderResult result = shared_renderer().compare(scene_, after, options);
  ASSERT_EQ(result.panels.size(), 1u);
  EXPECT_EQ(result.image.width, 800);
  EXPECT_EQ(result.image.height, 600);
  const Panel& panel = result.panels.front();
  const auto is_green = [](const std::uint8_t* p) { return p[1] > p[0] + 40 && p[1] > p[2] + 30; };
  const auto is_yellow = [](const std::uint8_t* p) {
    return p[0] > p[2] + 80 && p[1] > p[2] + 80 && std::abs(p[0] - p[1]) < 60;
  };
  const auto is_magenta = [](const std::uint8_t* p) {
    return p[0] > p[1] + 60 && p[2] > p[1] + 40;
  };
  const int tip = model_->frame_index("tip");
  dynamics::Data data(*model_);
  const auto tip_pixel = [&](const RenderScene& scene, double t) {
    dynamics::forward_kinematics(*model_, data, scene.trajectory.at(t));
    return panel.project(dynamics::frame_pose(*model_, data, tip).translation());
  };
  int green = 0, yellow = 0;
  for (double t : {0.3, 0.8, 1.2, 1.7}) {
    const auto b = tip_pixel(scene_, t), a = tip_pixel(after, t);
    ASSERT_TRUE(b && a);
    green += count_near(result.image, *b, 2, is_green) > 0;
    yellow += count_near(result.image, *a, 2, is_yellow) > 0;
  }
  EXPECT_GE(green, 3);
  EXPECT_GE(yellow, 3);
  // The second plan's last pose is solid red; the first's last pose is grey, not red.
  for (const Eigen::Vector3d& p : link_midpoints(after.trajectory.q.back())) {
    EXPECT_GE(count_near(result.image, *panel.project(p), 1, is_red), 5);
  }
  const Eigen::Vector3d before_elbow = link_midpoints(scene_.trajectory.q.back())[2];
  EXPECT_EQ(count_near(result.image, *panel.project(before_elbow), 1, is_red), 0);
  // The obstacle both plans have keeps its blue; the added one is magenta.
  EXPECT_GE(count_near(result.image, *panel.project(Eigen::Vector3d(0.0, -0.9, 0.3)), 2, is_blue),
            20);
  EXPECT_GE(
      count_near(result.image, *panel.project(Eigen::Vector3d(0.9, 0.6, 0.25)), 2, is_magenta), 20);
  if (const char* dump = std::getenv("KINOGRAPH_RENDER_TEST_OUT")) {
    write_png(result.image, std::string(dump) + "/compare.png");
  }
}

// A scene's fixed camera keeps its direction in the replanning figure but is moved to frame both
// plans' motions.
TEST_F(RedArm, CompareReframesAFixedCameraAlongItsDirection) {
  RenderScene after = scene_;
  after.trajectory =
      test::smooth_trajectory(scene_.trajectory.q.front(), Eigen::Vector3d(0.9, 0.5, 0.4));
  Camera fixed;
  fixed.eye = Eigen::Vector3d(20, -5, 3);  // far too far: the arm would be a few pixels
  fixed.target = Eigen::Vector3d(0, 0, 0.5);
  fixed.fov_y_deg = 35;
  after.camera = fixed;
  CompareOptions options;
  options.frame.width = 400;
  options.frame.height = 300;
  const Camera camera = shared_renderer().compare(scene_, after, options).panels.front().camera;
  EXPECT_TRUE((camera.eye - camera.target)
                  .normalized()
                  .isApprox((fixed.eye - fixed.target).normalized(), 1e-9));
  EXPECT_EQ(camera.fov_y_deg, fixed.fov_y_deg);
  EXPECT_LT((camera.eye - camera.target).norm(), 0.5 * (fixed.eye - fixed.target).norm());
  for (const RenderScene* scene : {&scene_, &after}) {
    for (const Eigen::Vector3d& p : shared_renderer().motion_points(*scene)) {
      const auto pixel = camera.project(p, 400, 300);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_TRUE(pixel->x() > -1e-6 && pixel->x() < 400 + 1e-6 && pixel->y() > -1e-6 &&
                  pixel->y() < 300 + 1e-6)
          << pixel->transpose();
    }
  }
  options.reframe_camera = false;  // then the scene's camera is used as it is
  const Camera kept = shared_renderer().compare(scene_, after, options).panels.front().camera;
  EXPECT_EQ(kept.eye, fixed.eye);
}

TEST_F(RedArm, ZeroFramesIsAClearError) {
  FrameOptions options;
  options.frames = 0;
  try {
    shared_renderer().strip(scene_, options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frames"), std::string::npos) << e.what();
  }
  EXPECT_THROW(shared_renderer().ghost(scene_, options), std::invalid_argument);
}

TEST_F(RedArm, MissingObstacleMeshNamesTheFile) {
  SceneObstacle mesh;
  mesh.obstacle.shape = collision::Shape::mesh("/nonexistent/kinograph/obstacle.stl");
  scene_.obstacles.push_back(mesh);
  try {
    shared_renderer().strip(scene_, FrameOptions{});
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/kinograph/obstacle.stl"), std::string::npos)
        << e.what();
  }
}

TEST_F(RedArm, BadTrajectoryIsAClearError) {
  scene_.trajectory.q[3] = Eigen::VectorXd::Zero(2);
  EXPECT_THROW(shared_renderer().strip(scene_, FrameOptions{}), std::invalid_argument);
  scene_.trajectory = Trajectory{};
  EXPECT_THROW(shared_renderer().strip(scene_, FrameOptions{}), std::invalid_argument);
}

TEST(PlanarRobot, SideViewLooksAlongTheJointAxes) {
  const std::string path = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/rr/rr.urdf";
  const dynamics::Model model = dynamics::Model::from_urdf_file(path);
  RenderScene scene;
  scene.model = &model;
  scene.trajectory = test::smooth_trajectory(Eigen::Vector2d(0.2, 0.4), Eigen::Vector2d(1.4, -0.8));
  const auto axis = planar_axis(model, scene.trajectory.q.front());
  ASSERT_TRUE(axis.has_value());
  const Camera camera = shared_renderer().auto_camera(scene, 1.0);
  const Eigen::Vector3d view = (camera.eye - camera.target).normalized();
  EXPECT_NEAR(std::abs(view.dot(*axis)), 1.0, 1e-9);
}

TEST(PlanarRobot, SpatialArmIsNotPlanar) {
  const dynamics::Model model = dynamics::Model::from_urdf_string(test::red_arm_urdf());
  EXPECT_FALSE(planar_axis(model, Eigen::VectorXd::Zero(3)).has_value());
}

// Barrett WAM from Debian's dart-doc: STL/DAE meshes written as package://herb_description/...
// with the URDF at the root of that package under another folder name; the Model's package://
// resolver falls back to the URDF's own folder for exactly this layout.
TEST(ThirdPartyMeshes, BarrettWamRenders) {
  const std::string dir = "/usr/share/doc/dart/data/urdf/wam";
  if (!std::filesystem::exists(dir + "/wam.urdf")) GTEST_SKIP() << "dart-doc is not installed";
  const dynamics::Model model = dynamics::Model::from_urdf_file(dir + "/wam.urdf");
  int meshes = 0;
  for (const dynamics::Geometry& g : model.visual) {
    if (g.shape == dynamics::Geometry::Shape::kMesh) ++meshes;
  }
  ASSERT_GE(meshes, 7);
  RenderScene scene;
  scene.model = &model;
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model.nq()), q1 = q0;
  q1[0] = 1.0;
  q1[1] = 0.8;
  q1[3] = 1.2;
  scene.trajectory = test::smooth_trajectory(q0, q1);
  FrameOptions options;
  options.frames = 3;
  options.width = 900;
  options.height = 400;
  options.floor = false;
  options.labels = false;
  const RenderResult result = shared_renderer().strip(scene, options);
  // Every body's origin region shows something that is not the white background (the WAM's
  // DAE materials are near white, so any non-background pixel counts).
  dynamics::Data data(model);
  for (const Panel& panel : result.panels) {
    dynamics::forward_kinematics(model, data, scene.trajectory.at(panel.time));
    int drawn = 0;
    for (int b = 0; b < model.nq(); ++b) {
      const auto pixel = panel.project(data.body_pose[b].translation());
      ASSERT_TRUE(pixel.has_value());
      drawn += count_near(result.image, *pixel, 3, [](const std::uint8_t* p) {
                 return p[0] != 255 || p[1] != 255 || p[2] != 255;
               }) > 0;
    }
    EXPECT_GE(drawn, model.nq() - 1) << "t = " << panel.time;
  }
  if (const char* dump = std::getenv("KINOGRAPH_RENDER_TEST_OUT")) {
    write_png(result.image, std::string(dump) + "/wam_strip.png");
  }
}

}  // namespace
}  // namespace kinograph::render
