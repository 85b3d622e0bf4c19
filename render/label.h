#pragma once
// Text on rendered pictures (frame times in strips), drawn with cairo and DejaVu Sans.
#include <Eigen/Core>
#include <string>

#include "render/image.h"

namespace kinograph::render {

/// Where a label's anchor point sits on its text box.
enum class LabelAnchor { kTopLeft, kTopCenter, kBottomCenter };

/// Draws `text` onto `image` at pixel (x, y) in the font size `size_px`, on a translucent
/// white box so it stays readable over the floor and the robot.
void draw_label(Image& image, const std::string& text, double x, double y, double size_px,
                LabelAnchor anchor = LabelAnchor::kTopCenter,
                const Eigen::Vector3d& color = Eigen::Vector3d(0.1, 0.1, 0.1));

}  // namespace kinograph::render
