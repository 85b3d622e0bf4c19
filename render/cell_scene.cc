#include "render/cell_scene.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace kinograph::render {

Eigen::Vector4d robot_colour(int i) {
  // Distinct hues that are neither the obstacles' blue nor the paths' red.
  static const std::array<Eigen::Vector4d, 8> kPalette = {
      Eigen::Vector4d(0.95, 0.55, 0.10, 1), Eigen::Vector4d(0.20, 0.65, 0.35, 1),
      Eigen::Vector4d(0.55, 0.35, 0.80, 1), Eigen::Vector4d(0.90, 0.80, 0.15, 1),
      Eigen::Vector4d(0.10, 0.70, 0.75, 1), Eigen::Vector4d(0.85, 0.35, 0.60, 1),
      Eigen::Vector4d(0.55, 0.45, 0.30, 1), Eigen::Vector4d(0.45, 0.50, 0.55, 1)};
  return kPalette[static_cast<std::size_t>(i) % kPalette.size()];
}

dynamics::Model colour_robots(const dynamics::Model& composite,
                              const std::vector<dynamics::ComposedRange>& ranges) {
  dynamics::Model out = composite;
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    const Eigen::Vector4d colour = robot_colour(static_cast<int>(r));
    const dynamics::ComposedRange& range = ranges[r];
    for (int g = range.visual_offset; g < range.visual_offset + range.visual_count; ++g) {
      dynamics::Geometry& geometry = out.visual[g];
      const double luminance = geometry.rgba.head<3>().dot(Eigen::Vector3d(0.3, 0.59, 0.11));
      geometry.rgba.head<3>() = colour.head<3>() * (0.45 + 0.55 * std::clamp(luminance, 0.0, 1.0));
    }
  }
  return out;
}

Trajectory cell_trajectory(const std::vector<Trajectory>& robots,
                           const std::vector<dynamics::ComposedRange>& ranges) {
  if (robots.size() != ranges.size() || robots.empty()) {
    throw std::invalid_argument("render: " + std::to_string(robots.size()) + " trajectories for " +
                                std::to_string(ranges.size()) + " robots");
  }
  std::vector<double> times;
  for (std::size_t r = 0; r < robots.size(); ++r) {
    if (robots[r].t.empty()) {
      throw std::invalid_argument("render: robot '" + ranges[r].name + "' has no trajectory");
    }
    times.insert(times.end(), robots[r].t.begin(), robots[r].t.end());
  }
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const int nq = ranges.back().offset + ranges.back().nq;
  Trajectory out;
  out.t = times;
  for (double t : times) {
    Eigen::VectorXd q(nq);
    for (std::size_t r = 0; r < robots.size(); ++r) {
      const Eigen::VectorXd qr = robots[r].at(t);
      if (qr.size() != ranges[r].nq) {
        throw std::invalid_argument("render: robot '" + ranges[r].name + "' has " +
                                    std::to_string(ranges[r].nq) + " joints, its plan " +
                                    std::to_string(qr.size()));
      }
      q.segment(ranges[r].offset, ranges[r].nq) = qr;
    }
    out.q.push_back(std::move(q));
  }
  return out;
}

std::vector<ScenePath> robot_paths(const std::vector<dynamics::ComposedRange>& ranges,
                                   const std::vector<std::string>& frames) {
  std::vector<ScenePath> paths;
  for (std::size_t r = 0; r < ranges.size() && r < frames.size(); ++r) {
    const Eigen::Vector4d c = robot_colour(static_cast<int>(r));
    paths.push_back({dynamics::composed_name(ranges[r].name, frames[r]),
                     Eigen::Vector4f(0.8f * c.x(), 0.8f * c.y(), 0.8f * c.z(), 1.f)});
  }
  return paths;
}

}  // namespace kinograph::render
