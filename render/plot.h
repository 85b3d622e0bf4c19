#pragma once
// Torque plots of plans (the paper's torque figure): one subplot per joint, its axes spanning
// the data, the effort limits dashed where they fall within (named at the edge where they lie
// beyond), several plans overlaid in different colours with a legend. Drawn with cairo.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "render/image.h"

namespace kinograph::render {

/// One curve set: a plan's joint values (torques) over time, named in the legend.
struct PlotSeries {
  std::string label;
  std::vector<double> t;
  std::vector<Eigen::VectorXd> values;  ///< one vector per time, one entry per joint
};

/// Layout and labels of a torque plot; defaults suit a 7-joint arm.
struct TorquePlotOptions {
  int width = 1200;
  int height = 0;   ///< 0: 210 pixels per row of subplots plus the title
  int columns = 0;  ///< subplot columns; 0: 1 for up to 3 joints, else 2
  std::string title = "Joint torques";
  std::string y_label = "\u03c4 [N\u00b7m]";
  std::string x_label = "t [s]";  ///< under each subplot's axis (e.g. "steps" for a scaling plot)
  std::vector<std::string> joint_names;  ///< subplot titles; "joint i" when empty
  /// ±limit per joint, dashed within the axes, else named at the edge; inf or empty = none
  std::vector<double> limits;
};

/// Round tick values covering [lo, hi] (about `target` of them, steps of 1, 2 or 5 × 10^k).
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

/// The colour of the i-th series (RGB in 0..1), so tests and captions can name it.
Eigen::Vector3d series_color(int i);

/// Draws the torque plot. Throws std::invalid_argument if there is no series, a series is
/// empty, or the series disagree on the number of joints.
Image plot_torques(const std::vector<PlotSeries>& series, const TorquePlotOptions& options = {});

}  // namespace kinograph::render
