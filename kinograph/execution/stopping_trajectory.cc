#include "kinograph/execution/stopping_trajectory.h"

#include <cmath>
#include <stdexcept>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/planning/validate.h"

namespace kinograph::execution {
namespace {

// Knots at most this far apart on a stop, so that validate's between-knot samples are dense.
constexpr double kMaxKnotSpacingS = 0.05;

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += (text.empty() ? "" : "; ") + line;
  return text;
}

}  // namespace

planning::Plan linear_acceleration_plan(const dynamics::Model& model, const Eigen::VectorXd& q0,
                                        const Eigen::VectorXd& qd0,
                                        const std::vector<double>& times,
                                        const std::vector<Eigen::VectorXd>& accelerations,
                                        int knots_per_piece) {
  const Eigen::Index n = model.nq();
  if (q0.size() != n || qd0.size() != n) {
    throw std::invalid_argument("linear_acceleration_plan: q0 and qd0 need one entry per joint");
  }
  if (times.size() < 2 || times.size() != accelerations.size() || times.front() != 0) {
    throw std::invalid_argument(
        "linear_acceleration_plan: needs >= 2 breakpoints from t = 0, one acceleration each");
  }
  if (knots_per_piece < 1) {
    throw std::invalid_argument("linear_acceleration_plan: knots_per_piece must be >= 1");
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (accelerations[i].size() != n) {
      throw std::invalid_argument("linear_acceleration_plan: acceleration " + std::to_string(i) +
                                  " needs one entry per joint");
    }
    if (i > 0 && !(times[i] > times[i - 1])) {
      throw std::invalid_argument("linear_acceleration_plan: times must increase");
    }
  }
  const int pieces = static_cast<int>(times.size()) - 1;
  const int knots = pieces * knots_per_piece + 1;
  planning::Plan plan;
  plan.t.resize(knots);
  plan.q.resize(knots, n);
  plan.qd.resize(knots, n);
  plan.qdd.resize(knots, n);
  plan.tau.resize(knots, n);
  Eigen::VectorXd q = q0, qd = qd0;
  plan.t[0] = 0;
  plan.q.row(0) = q0.transpose();
  plan.qd.row(0) = qd0.transpose();
  plan.qdd.row(0) = accelerations[0].transpose();
  for (int p = 0; p < pieces; ++p) {
    const double length = times[p + 1] - times[p];
    const Eigen::VectorXd& a = accelerations[p];
    const Eigen::VectorXd jerk = (accelerations[p + 1] - a) / length;
    for (int i = 1; i <= knots_per_piece; ++i) {
      // The cubic of constant jerk from the piece's start (docs/interpolation.md).
      const double s = length * i / knots_per_piece;
      const int k = p * knots_per_piece + i;
      plan.t[k] = times[p] + s;
      plan.q.row(k) = (q + qd * s + a * (s * s / 2) + jerk * (s * s * s / 6)).transpose();
      plan.qd.row(k) = (qd + a * s + jerk * (s * s / 2)).transpose();
      plan.qdd.row(k) = (a + jerk * s).transpose();
    }
    // The next piece starts from this one's end, as computed from this piece's own cubic.
    q = plan.q.row((p + 1) * knots_per_piece).transpose();
    qd = plan.qd.row((p + 1) * knots_per_piece).transpose();
  }
  plan.qdd.row(knots - 1) = accelerations.back().transpose();
  dynamics::Data data(model);
  for (int k = 0; k < knots; ++k) {
    plan.tau.row(k) = dynamics::rnea(model, data, plan.q.row(k).transpose(),
                                     plan.qd.row(k).transpose(), plan.qdd.row(k).transpose())
                          .transpose();
  }
  plan.stats.method = "stop";
  return plan;
}

StoppingTrajectory stopping_trajectory(const planning::Problem& world, const Eigen::VectorXd& q,
                                       const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const dynamics::Model& model = *world.model;
  const Eigen::Index n = model.nq();
  if (q.size() != n || qd.size() != n || qdd.size() != n) {
    throw std::invalid_argument("stopping_trajectory: q, qd, qdd need one entry per joint of '" +
                                model.name + "'");
  }
  StoppingTrajectory stop;
  for (double T = kShortestStopS; T <= kLongestStopS * (1 + 1e-9); T *= 2) {
    const Eigen::VectorXd a_m = -(2 * qd + qdd * (T / 2)) / T;
    const int per_piece = std::max(1, static_cast<int>(std::ceil(T / 2 / kMaxKnotSpacingS)));
    planning::Plan plan = linear_acceleration_plan(model, q, qd, {0, T / 2, T},
                                                   {qdd, a_m, Eigen::VectorXd::Zero(n)}, per_piece);
    planning::Problem problem = world;
    problem.horizon = T;
    problem.steps = static_cast<int>(plan.t.size()) - 1;
    problem.start_q = q;
    problem.start_qd = qd;
    problem.goal = planning::Goal{};
    problem.goal.q = plan.q.bottomRows(1).transpose();
    problem.task_constraints.clear();
    plan.validation = planning::validate(problem, plan);
    stop.duration_s = T;
    if (plan.validation.valid) {
      stop.valid = true;
      stop.reason.clear();
      stop.plan = std::move(plan);
      return stop;
    }
    stop.reason = "a stop in " + std::to_string(T) + " s: " + joined(plan.validation.failures);
    stop.plan = std::move(plan);
  }
  stop.reason = "no stop of " + std::to_string(kShortestStopS) + " to " +
                std::to_string(kLongestStopS) + " s validates; " + stop.reason;
  return stop;
}

}  // namespace kinograph::execution
