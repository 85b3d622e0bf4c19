// Failed plans' pictures: which plans count as failed, and the red frame and banner drawn
// over a picture (checked pixel by pixel), the picture's middle left as it was.
#include "render/failure_mark.h"

#include <gtest/gtest.h>

namespace kinograph::render {
namespace {

bool is_red(const Image& image, int x, int y) {
  const std::uint8_t* p = image.at(x, y);
  return p[0] > 180 && p[1] < 60 && p[2] < 60;
}

TEST(FailureMark, TextSaysWhyOnlyForFailedPlans) {
  planning::Plan plan;
  EXPECT_FALSE(failure_text(plan)) << "a file with no verdict is not called failed";
  plan.validation.valid = true;
  EXPECT_FALSE(failure_text(plan));
  plan.validation.valid = false;
  plan.validation.failures = {"goal error 0.2 exceeds 0.01", "min clearance -0.01 below 0"};
  EXPECT_EQ(failure_text(plan), "FAILED PLAN: goal error 0.2 exceeds 0.01 (+1 more)");
  plan.validation.failures.clear();
  plan.stats.status = planning::PlanStatus::kInfeasible;
  plan.stats.reason = "constraints violated after 200 iterations";
  EXPECT_EQ(failure_text(plan),
            "FAILED PLAN: infeasible: constraints violated after 200 iterations");
}

TEST(FailureMark, RedFrameAndBannerOverThePicture) {
  Image image(600, 300, 255, 255, 255);
  mark_failed(image, "FAILED PLAN: goal error 0.2 exceeds 0.01");
  ASSERT_EQ(image.width, 600);
  ASSERT_EQ(image.height, 300);
  // The frame: every edge pixel is red.
  for (int x = 0; x < 600; x += 7) {
    EXPECT_TRUE(is_red(image, x, 299)) << x;
    EXPECT_TRUE(is_red(image, x, 0)) << x;
  }
  for (int y = 0; y < 300; y += 7) {
    EXPECT_TRUE(is_red(image, 0, y)) << y;
    EXPECT_TRUE(is_red(image, 599, y)) << y;
  }
  // The banner: red with white text in it; above it the picture is untouched.
  int red = 0, white = 0;
  for (int y = 270; y < 295; ++y) {
    for (int x = 10; x < 590; ++x) {
      const std::uint8_t* p = image.at(x, y);
      red += is_red(image, x, y);
      white += p[0] > 200 && p[1] > 200 && p[2] > 200;
    }
  }
  EXPECT_GT(red, 580 * 25 / 2);
  EXPECT_GT(white, 200);
  const std::uint8_t* middle = image.at(300, 100);
  EXPECT_EQ(middle[0], 255);
  EXPECT_EQ(middle[1], 255);
  EXPECT_EQ(middle[2], 255);
}

}  // namespace
}  // namespace kinograph::render
