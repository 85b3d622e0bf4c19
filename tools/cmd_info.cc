// `kinograph info URDF [--q v1,v2,...]`: what the planner sees of a robot — its joint table,
// masses and the gravity torques it must hold at a configuration.
#include <spdlog/fmt/fmt.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/model.h"
#include "tools/command_registry.h"
#include "tools/number_list.h"

namespace kinograph::tools {
namespace {

struct InfoArgs {
  std::string urdf;
  std::string q;
};

// "0.1,pi/2,..." → exactly n joint positions (all zero when empty).
Eigen::VectorXd parse_configuration(const std::string& text, int n) {
  if (text.empty()) return Eigen::VectorXd::Zero(n);
  const std::vector<double> q = parse_number_list(text, "--q");
  if (static_cast<int>(q.size()) != n) {
    throw CommandFailure(
        fmt::format("--q: the robot has {} joints but {} values were given", n, q.size()));
  }
  return Eigen::Map<const Eigen::VectorXd>(q.data(), n);
}

std::string limit(double v) {
  return std::isinf(v) ? (v > 0 ? "inf" : "-inf") : fmt::format("{:.4g}", v);
}

void run_info(const InfoArgs& args) {
  dynamics::Model model;
  try {
    model = dynamics::Model::from_urdf_file(args.urdf);
  } catch (const dynamics::UrdfError& e) {
    throw CommandFailure(e.what());
  }
  const int n = model.nq();
  const Eigen::VectorXd q = parse_configuration(args.q, n);

  fmt::print("robot '{}' from {}\n", model.name, model.urdf_path);
  fmt::print("{} joints, {} frames, {} collision and {} visual shapes\n\n", n, model.frames.size(),
             model.collision.size(), model.visual.size());
  fmt::print(
      "| # | joint | link | parent | type | axis | lower | upper | velocity | effort | "
      "damping | actuated |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < n; ++i) {
    const dynamics::Body& b = model.bodies[i];
    const bool revolute = b.joint_type == dynamics::JointType::kRevolute;
    const Eigen::Vector3d axis = revolute ? b.screw_axis.head<3>() : b.screw_axis.tail<3>();
    const std::string type =
        revolute ? (std::isinf(b.limits.lower) ? "continuous" : "revolute") : "prismatic";
    fmt::print(
        "| {} | {} | {} | {} | {} | ({:.3g}, {:.3g}, {:.3g}) | {} | {} | {} | {} | {:.4g} | "
        "{} |\n",
        i, b.joint_name, b.name, b.parent < 0 ? "base" : model.bodies[b.parent].name, type,
        axis.x(), axis.y(), axis.z(), limit(b.limits.lower), limit(b.limits.upper),
        limit(b.limits.velocity), limit(b.limits.effort), b.damping, b.actuated ? "yes" : "no");
  }
  fmt::print("\ntotal mass {:.4f} kg (moving links {:.4f} kg, fixed base {:.4f} kg)\n",
             model.total_mass() + model.base_mass, model.total_mass(), model.base_mass);

  dynamics::Data data(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd& tau = dynamics::rnea(model, data, q, zero, zero);
  fmt::print("\ngravity torques at q = [");
  for (int i = 0; i < n; ++i) fmt::print("{}{:.6g}", i ? ", " : "", q[i]);
  fmt::print("] (g = [{:.4g}, {:.4g}, {:.4g}] m/s²):\n", model.gravity.x(), model.gravity.y(),
             model.gravity.z());
  for (int i = 0; i < n; ++i) {
    const dynamics::Body& b = model.bodies[i];
    const bool revolute = b.joint_type == dynamics::JointType::kRevolute;
    const bool over = std::abs(tau[i]) > b.limits.effort;
    fmt::print("  {:<24} {:>12.6f} {}{}\n", b.joint_name, tau[i], revolute ? "N·m" : "N",
               over ? (b.actuated ? "  (exceeds effort limit)" : "  (unactuated)") : "");
  }
}

const bool kInfoRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = root.add_subcommand(
      "info", "Print a robot's joint table, total mass and gravity torques at a configuration");
  cmd->add_option("urdf", args->urdf, "Robot description (URDF file)")->required();
  cmd->add_option("--q", args->q,
                  "Joint positions (rad, or m for prismatic joints), comma-separated, one per "
                  "joint; angles may use pi (pi/2); default: all zero. Write --q=-0.5,1.2 when "
                  "the first value is negative");
  cmd->callback([args] { run_info(*args); });
});

}  // namespace
}  // namespace kinograph::tools
