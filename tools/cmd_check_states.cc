// What a robot actually did, from its recorded states:
//   kinograph check-states LOG.lcmlog --scene S [--change C] [--channel IIWA_STATE] [--goal Q]
//                          [--out EXECUTED.json]
// Reads the robot_state_t messages of one channel from an LCM log (lcm-logger) and prints, as
// "key value" lines: how many, their first and last utime, the smallest clearance of the
// recorded configurations to the scene's obstacles (plus a change file's), its floor and the
// robot's own links (the validator's clearance world), the final state's clearance, distance to
// the goal and speed. --out writes the recorded states as a plan file (t, q, q̇; no q̈ or τ, no
// verdict) to draw the executed path with `kinograph render`.
#include <Eigen/Core>
#include <cmath>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <memory>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/io/replan_change.h"
#include "kinograph/planning/io/scene.h"
#include "lcmtypes/safe_decode.h"
#include "tools/command_registry.h"
#include "tools/number_list.h"
#include "tools/plan_file.h"

namespace kinograph::tools {
namespace {

const bool kCheckStates = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "check-states", "clearance and arrival of the robot states recorded in an LCM log");
  auto log = std::make_shared<std::string>();
  auto scene = std::make_shared<std::string>();
  auto change = std::make_shared<std::string>();
  auto channel = std::make_shared<std::string>("IIWA_STATE");
  auto goal = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  sub->add_option("log", *log, "LCM log file (lcm-logger)")->required();
  sub->add_option("--scene", *scene, "the robot's scene (robot, obstacles, floor)")->required();
  sub->add_option("--change", *change,
                  "a change file whose obstacles are also checked (robots/scenes/changes/)");
  sub->add_option("--channel", *channel, "state channel (default IIWA_STATE)");
  sub->add_option("--goal", *goal,
                  "joint goal, comma-separated, rad, for the final error (default: the scene's)");
  sub->add_option("--out", *out,
                  "also write the recorded states as a plan file (JSON) of the executed path");
  sub->callback([=] {
    planning::Scene s;
    try {
      s = planning::load_scene(*scene);
      if (!change->empty()) s = planning::apply_change(s, planning::load_change(*change, s));
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
    const dynamics::Model& model = *s.problem.model;
    Eigen::VectorXd goal_q = s.problem.goal.q;
    if (!goal->empty()) {
      const std::vector<double> v =
          parse_number_list(*goal, "--goal", static_cast<std::size_t>(model.nq()));
      goal_q = Eigen::Map<const Eigen::VectorXd>(v.data(), model.nq());
    }
    std::unique_ptr<collision::CollisionWorld> world = planning::clearance_world(s.problem);
    dynamics::Data data(model);
    messages::RobotIdentity identity{model.name, ""};
    lcm::LogFile file(*log, "r");
    if (!file.good()) throw CommandFailure("cannot read LCM log " + *log);
    long states = 0, refused = 0;
    int64_t first = 0, last = 0;
    double min_clearance = std::numeric_limits<double>::infinity(), final_clearance = 0;
    std::string closest_pair = "none";
    int64_t closest_utime = 0;
    messages::MeasuredState state;
    std::vector<messages::MeasuredState> recorded;
    while (const lcm::LogEvent* event = file.readNextEvent()) {
      if (event->channel != *channel) continue;
      robot_state_t msg;
      messages::MeasuredState m;
      if (!lcmtypes::safe_decode(event->data, event->datalen, msg).ok ||
          !messages::state_from_message(msg, model, identity, m).ok) {
        ++refused;
        continue;
      }
      if (states == 0) first = m.utime;
      last = m.utime;
      ++states;
      dynamics::forward_kinematics(model, data, m.q);
      const collision::Proximity p = world->closest(data);
      final_clearance = p.distance;
      if (p.distance < min_clearance) {
        min_clearance = p.distance;
        closest_pair = planning::describe_pair(model, p);
        closest_utime = m.utime;
      }
      if (!out->empty()) recorded.push_back(m);
      state = std::move(m);
    }
    if (states == 0)
      throw CommandFailure("no robot_state_t of '" + model.name + "' on " + *channel);
    std::cout << "states " << states << "\nrefused " << refused << "\nfirst_utime " << first
              << "\nlast_utime " << last << "\nmin_clearance " << min_clearance
              << "\nclosest_utime " << closest_utime << "\nfinal_clearance " << final_clearance
              << "\nfinal_goal_error " << (state.q - goal_q).cwiseAbs().maxCoeff()
              << "\nfinal_speed " << state.qd.cwiseAbs().maxCoeff() << "\n";
    std::cout << "closest_pair " << closest_pair << "\n";
    if (out->empty()) return;
    // The executed path as a plan file: knots at the recorded states (strictly later ones).
    planning::Plan executed;
    executed.stats.method = "executed (recorded states)";
    std::vector<const messages::MeasuredState*> knots;
    for (const auto& r : recorded) {
      if (knots.empty() || r.utime > knots.back()->utime) knots.push_back(&r);
    }
    const Eigen::Index n = model.nq(), rows = static_cast<Eigen::Index>(knots.size());
    executed.q.resize(rows, n);
    executed.qd.resize(rows, n);
    executed.qdd = Eigen::MatrixXd::Zero(rows, n);
    executed.tau = Eigen::MatrixXd::Zero(rows, n);
    for (Eigen::Index k = 0; k < rows; ++k) {
      executed.t.push_back(static_cast<double>(knots[k]->utime - first) * 1e-6);
      executed.q.row(k) = knots[k]->q.transpose();
      executed.qd.row(k) = knots[k]->qd.transpose();
    }
    write_plan_json(executed, s, *out);
    std::cout << "executed path written to " << *out << "\n";
  });
});

}  // namespace
}  // namespace kinograph::tools
