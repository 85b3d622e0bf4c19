#pragma once
// Seeded random crossing-goal problems for N iiwa arms around a shared table, written as cell
// files (robots/cells/README.md). Layout: two arms face each other across a box table, bases
// 1.3 m apart; more arms stand on a circle around a round table, facing its centre. Each hand
// starts over the table on its robot's left and ends reaching towards the middle on its right,
// so neighbours' paths cross. Every start and goal is within the joint limits (0.2 rad inside),
// clear of the table and the floor by the collision ε, clear of the robot's own links, and
// the robots' starts (and goals) are clear of each other by `robot_clearance`.
#include <cstdint>
#include <string>

namespace kinograph::bench {

/// What to generate; the defaults are the benchmark's.
struct CellGeneratorOptions {
  int robots = 2;              ///< N ≥ 2
  std::uint64_t seed = 1;      ///< problem seed (with robots, gives the same cell every time)
  double horizon = 3.0;        ///< s
  int steps = 30;              ///< intervals
  double robot_clearance = 0.08;  ///< m between any links of two robots at the start and goal
  std::string urdf;            ///< iiwa URDF (absolute); the SRDF beside it is used too
  int max_draws = 20000;       ///< joint samples per start or goal before giving up
};

/// The YAML text of one random cell; `name` is its name. Throws std::runtime_error when a
/// start or goal cannot be drawn within max_draws.
std::string generate_cell(const CellGeneratorOptions& options, const std::string& name);

}  // namespace kinograph::bench
