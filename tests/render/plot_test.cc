// Torque plots: tick choice, picture size, the curves' and limits' colours, bad input.
#include "render/plot.h"

#include <gtest/gtest.h>

#include <cmath>

namespace kinograph::render {
namespace {

PlotSeries sine_series(const std::string& label, double amplitude, int joints) {
  PlotSeries s;
  s.label = label;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.03 * k;
    s.t.push_back(t);
    Eigen::VectorXd v(joints);
    for (int j = 0; j < joints; ++j) v[j] = amplitude * std::sin(2.0 * t + j);
    s.values.push_back(v);
  }
  return s;
}

int count_colour(const Image& image, const Eigen::Vector3d& rgb, int tolerance) {
  int count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, y);
      if (std::abs(p[0] - rgb.x() * 255) <= tolerance &&
          std::abs(p[1] - rgb.y() * 255) <= tolerance &&
          std::abs(p[2] - rgb.z() * 255) <= tolerance) {
        ++count;
      }
    }
  }
  return count;
}

TEST(NiceTicks, RoundStepsCoveringTheRange) {
  const std::vector<double> unit = nice_ticks(0.0, 1.0, 5);
  const std::vector<double> expected = {0.0, 0.2, 0.4, 0.6, 0.8, 1.0};
  ASSERT_EQ(unit.size(), expected.size());
  for (std::size_t i = 0; i < unit.size(); ++i) EXPECT_NEAR(unit[i], expected[i], 1e-12);
  const std::vector<double> ticks = nice_ticks(-337.0, 341.0, 5);
  ASSERT_EQ(ticks.size(), 7u);  // step 100 (7 ticks) is as near to 5 as step 200 (3): finer wins
  const double step = ticks[1] - ticks[0];
  EXPECT_DOUBLE_EQ(step, 100.0);
  EXPECT_GE(ticks.front(), -337.0);
  EXPECT_LE(ticks.back(), 341.0);
  EXPECT_LT(ticks.front() - step, -337.0);
  EXPECT_GT(ticks.back() + step, 341.0);
  EXPECT_NE(std::find(ticks.begin(), ticks.end(), 0.0), ticks.end());
  EXPECT_TRUE(nice_ticks(1.0, 1.0).empty());
}

TEST(TorquePlot, SizeCurvesLimitsAndOverlay) {
  TorquePlotOptions options;
  options.width = 1000;
  options.limits = {25, 25, 25, 25};  // within the curves' ±30: drawn
  const Image one = plot_torques({sine_series("batch", 30, 4)}, options);
  EXPECT_EQ(one.width, 1000);
  EXPECT_EQ(one.height, 44 + 2 * 210);  // 4 joints: 2 columns, 2 rows
  EXPECT_GT(count_colour(one, series_color(0), 30), 500);
  EXPECT_EQ(count_colour(one, series_color(1), 30), 0);
  EXPECT_GT(count_colour(one, Eigen::Vector3d(0.8, 0.1, 0.1), 30), 300);  // dashed limits
  const Image two =
      plot_torques({sine_series("batch", 30, 4), sine_series("min torque", 15, 4)}, options);
  EXPECT_GT(count_colour(two, series_color(1), 30), 500);
  options.limits.clear();
  options.height = 300;
  const Image no_limits = plot_torques({sine_series("batch", 30, 4)}, options);
  EXPECT_EQ(no_limits.height, 300);
  EXPECT_LT(count_colour(no_limits, Eigen::Vector3d(0.8, 0.1, 0.1), 30), 20);
}

// Rows of the picture where the i-th series is drawn.
int rows_with(const Image& image, int i) {
  const Eigen::Vector3d rgb = series_color(i) * 255;
  int rows = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.at(x, y);
      if (std::abs(p[0] - rgb.x()) <= 30 && std::abs(p[1] - rgb.y()) <= 30 &&
          std::abs(p[2] - rgb.z()) <= 30) {
        ++rows;
        break;
      }
    }
  }
  return rows;
}

// The axes span the data: a limit far beyond the torques neither squashes the curves nor is
// drawn as a line, but is named at the edge (red text only).
TEST(TorquePlot, AxesSpanTheDataNotALimitFarBeyond) {
  TorquePlotOptions options;
  options.width = 600;
  const PlotSeries series = sine_series("batch", 30, 1);
  const Image plain = plot_torques({series}, options);
  options.limits = {400};
  const Image far = plot_torques({series}, options);
  EXPECT_EQ(rows_with(far, 0), rows_with(plain, 0));
  EXPECT_GT(rows_with(plain, 0), 120);  // most of the 210-pixel row minus the margins
  const int red = count_colour(far, Eigen::Vector3d(0.8, 0.1, 0.1), 30);
  EXPECT_GT(red, 0);
  EXPECT_LT(red, 300);  // the two labels (and the legend's dash), no lines across the axes
  options.limits = {25};
  EXPECT_GT(count_colour(plot_torques({series}, options), Eigen::Vector3d(0.8, 0.1, 0.1), 30),
            red + 300);  // within the data: both dashed lines
}

// The x label is the caller's: a scaling plot says "steps", not the default "t [s]".
TEST(TorquePlot, XLabelIsAnOption) {
  TorquePlotOptions options;
  options.width = 600;
  const PlotSeries series = sine_series("batch", 30, 1);
  EXPECT_EQ(options.x_label, "t [s]");
  const Image time_axis = plot_torques({series}, options);
  EXPECT_EQ(plot_torques({series}, options).rgba, time_axis.rgba);  // deterministic
  options.x_label = "steps";
  EXPECT_NE(plot_torques({series}, options).rgba, time_axis.rgba);
}

TEST(TorquePlot, BadInputIsAClearError) {
  EXPECT_THROW(plot_torques({}), std::invalid_argument);
  PlotSeries empty;
  empty.label = "empty";
  EXPECT_THROW(plot_torques({empty}), std::invalid_argument);
  EXPECT_THROW(plot_torques({sine_series("a", 1, 3), sine_series("b", 1, 4)}),
               std::invalid_argument);
}

}  // namespace
}  // namespace kinograph::render
