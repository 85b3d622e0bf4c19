// Camera matrices and automatic framing.
#include "render/camera.h"

#include <gtest/gtest.h>

#include <random>

namespace kinograph::render {
namespace {

TEST(Camera, TargetProjectsToTheCentre) {
  Camera camera;
  camera.eye = Eigen::Vector3d(2, -3, 1.5);
  camera.target = Eigen::Vector3d(0.1, 0.2, 0.6);
  const auto pixel = camera.project(camera.target, 640, 480);
  ASSERT_TRUE(pixel.has_value());
  EXPECT_NEAR(pixel->x(), 320, 1e-9);
  EXPECT_NEAR(pixel->y(), 240, 1e-9);
  // Up projects above the target (smaller y), the camera's right to larger x.
  EXPECT_LT(camera.project(camera.target + Eigen::Vector3d(0, 0, 0.1), 640, 480)->y(), 240);
  const Eigen::Vector3d right = (camera.target - camera.eye).cross(camera.up).normalized();
  EXPECT_GT(camera.project(camera.target + 0.1 * right, 640, 480)->x(), 320);
  EXPECT_FALSE(camera.project(camera.eye + (camera.eye - camera.target), 640, 480).has_value());
}

TEST(Camera, ViewIsARigidTransform) {
  Camera camera;
  const Eigen::Matrix4d v = camera.view();
  const Eigen::Matrix3d r = v.topLeftCorner<3, 3>();
  EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_TRUE((v * camera.eye.homogeneous()).head<3>().isZero(1e-12));
}

TEST(Camera, FramePointsKeepsEveryPointInsideAndCentred) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(2 + u(rng), 0.5 * u(rng), 1 + 0.8 * u(rng));
  for (double aspect : {0.5, 1.0, 4.0}) {
    const Camera camera = frame_points(points, Eigen::Vector3d(1, -1.2, 0.7).normalized(), aspect);
    const int w = static_cast<int>(400 * aspect), h = 400;
    double lo_x = 1e9, hi_x = -1e9, lo_y = 1e9, hi_y = -1e9;
    for (const Eigen::Vector3d& p : points) {
      const auto px = camera.project(p, w, h);
      ASSERT_TRUE(px.has_value());
      lo_x = std::min(lo_x, px->x());
      hi_x = std::max(hi_x, px->x());
      lo_y = std::min(lo_y, px->y());
      hi_y = std::max(hi_y, px->y());
    }
    EXPECT_GE(lo_x, 0);
    EXPECT_LE(hi_x, w);
    EXPECT_GE(lo_y, 0);
    EXPECT_LE(hi_y, h);
    // Centred and tight in at least one direction (the margin is 6% per side).
    EXPECT_NEAR(lo_x + hi_x, w, 0.02 * w);
    EXPECT_NEAR(lo_y + hi_y, h, 0.02 * h);
    EXPECT_TRUE(hi_x - lo_x > 0.8 * w || hi_y - lo_y > 0.8 * h);
  }
}

TEST(Camera, FrameBoundsSeesAllCorners) {
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -0.5, 0), Eigen::Vector3d(1, 0.5, 1.3));
  const Camera camera = frame_bounds(box, Eigen::Vector3d(0, -1, 0), 2.0);
  for (int i = 0; i < 8; ++i) {
    const auto px =
        camera.project(box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)), 800, 400);
    ASSERT_TRUE(px.has_value());
    EXPECT_GE(px->x(), 0);
    EXPECT_LE(px->x(), 800);
    EXPECT_GE(px->y(), 0);
    EXPECT_LE(px->y(), 400);
  }
}

}  // namespace
}  // namespace kinograph::render
