#pragma once
// Seeded random crossing-goal problems for N iiwa arms around a shared table, written as cell
// files (robots/cells/README.md). Layout: two arms face each other across a box table, bases
// 1.3 m apart; more arms stand on a circle around a round table, facing its centre. Each hand
// starts over the table on its robot's left and ends on its right, both towards the middle, and
// a problem is kept only when the robots' straight joint-space lines, run together, collide (so
// it needs coordination); else the next one is drawn. Every start and goal is within the joint
// limits (0.2 rad inside), clear of the table and the floor by the collision ε, clear of the
// robot's own links, and the robots' starts (and goals) are clear of each other by
// `robot_clearance`.
#include <cstdint>
#include <string>

namespace kinograph::bench {

/// What to generate; the defaults are the benchmark's.
struct CellGeneratorOptions {
  int robots = 2;                 ///< N ≥ 2
  std::uint64_t seed = 1;         ///< problem seed (with robots, gives the same cell every time)
  double horizon = 3.0;           ///< s
  int steps = 30;                 ///< intervals
  double robot_clearance = 0.08;  ///< m between any links of two robots at the start and goal
  /// The iiwa URDF as written in the cell (absolute, or relative to `path`'s folder); the
  /// SRDF beside it is named too.
  std::string urdf;
  std::string path;        ///< where the cell will be read from (anchors relative paths)
  int max_draws = 20000;   ///< joint samples per start or goal before giving up
  int max_problems = 200;  ///< problems drawn until one is crossing, before giving up
};

/// The YAML text of one random cell; `name` is its name. Throws std::runtime_error when a
/// start or goal cannot be drawn within max_draws.
std::string generate_cell(const CellGeneratorOptions& options, const std::string& name);

}  // namespace kinograph::bench
