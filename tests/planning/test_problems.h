#pragma once
// Small planning problems shared by the planner's end-to-end tests: the Acrobot swing-up, the RR
// arm reaching past a ball, and the iiwa carrying a 2 kg block past a box.
#include <Eigen/Core>
#include <gtest/gtest.h>
#include <cmath>
#include <memory>
#include <string>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/payload.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/plan.h"
#include "kinograph/planning/problem.h"

namespace kinograph::planning::testing {

/// An axis-aligned box obstacle of the given size centred at `at`.
inline collision::Obstacle box_obstacle(int id, const Eigen::Vector3d& size,
                                        const Eigen::Vector3d& at) {
  collision::Obstacle o;
  o.id = id;
  o.shape = collision::Shape::box(size.x(), size.y(), size.z());
  o.pose.translation() = at;
  return o;
}

/// A plan's method, status, reason and validation failures on one line, for test messages.
inline std::string failures(const Plan& p) {
  std::string s = p.stats.method + " " + to_string(p.stats.status) + " " + p.stats.reason + ":";
  for (const auto& f : p.validation.failures) s += " | " + f;
  return s;
}

// Every verdict, failure and figure of two validations is the same.
inline void expect_same_validation(const Validation& v, const Validation& w) {
  EXPECT_EQ(v.valid, w.valid);
  EXPECT_EQ(v.failures, w.failures);
  EXPECT_EQ(v.max_dynamics_residual, w.max_dynamics_residual);
  EXPECT_EQ(v.max_position_consistency, w.max_position_consistency);
  EXPECT_EQ(v.max_velocity_consistency, w.max_velocity_consistency);
  EXPECT_EQ(v.max_q_violation, w.max_q_violation);
  EXPECT_EQ(v.max_qd_violation, w.max_qd_violation);
  EXPECT_EQ(v.max_qdd_violation, w.max_qdd_violation);
  EXPECT_EQ(v.max_tau_violation, w.max_tau_violation);
  EXPECT_EQ(v.max_tau_violation_between, w.max_tau_violation_between);
  EXPECT_EQ(v.max_unactuated_torque_between, w.max_unactuated_torque_between);
  EXPECT_EQ(v.min_clearance, w.min_clearance);
  EXPECT_EQ(v.goal_error, w.goal_error);
  EXPECT_EQ(v.max_task_error, w.max_task_error);
  EXPECT_EQ(v.max_unactuated_torque, w.max_unactuated_torque);
  EXPECT_EQ(v.start_error, w.start_error);
  EXPECT_EQ(v.final_velocity, w.final_velocity);
}

inline std::shared_ptr<const dynamics::Model> load_robot(const std::string& rel) {
  return std::make_shared<const dynamics::Model>(
      dynamics::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/" + rel));
}

/// The Acrobot as its shipped scene declares it: the URDF with the shoulder unactuated.
inline std::shared_ptr<const dynamics::Model> acrobot_model() {
  return load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/acrobot_swingup.yaml")
      .problem.model;
}

/// Rest to upright in 10 s over 100 steps, elbow limited by the URDF's ±8 N·m.
inline Problem acrobot_swingup() {
  Problem p;
  p.name = "acrobot_swingup";
  p.model = acrobot_model();
  p.horizon = 10;
  p.steps = 100;
  p.start_q = Eigen::Vector2d(0, 0);
  p.start_qd = Eigen::Vector2d(0, 0);
  p.goal.q = Eigen::Vector2d(M_PI, 0);
  return p;
}

/// The Acrobot with an elbow far too weak (±0.2 N·m) to swing it up, and options `o` set for
/// one attempt at it (no restarts, no continuation in the effort limits).
inline Problem weak_elbow_acrobot(BatchPlannerOptions& o) {
  Problem p =
      load_scene(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/acrobot_swingup.yaml").problem;
  auto weak = std::make_shared<dynamics::Model>(*p.model);
  weak->bodies[1].limits.effort = 0.2;
  p.model = weak;
  o.max_restarts = 0;
  o.effort_continuation.clear();
  return p;
}

/// The RR arm swings from one side to the other past a ball its straight line would hit.
inline Problem rr_reach() {
  Problem p;
  p.name = "rr_reach";
  p.model = load_robot("robots/rr/rr.urdf");
  p.horizon = 3;
  p.steps = 30;
  p.start_q = Eigen::Vector2d(-1.2, 0);
  p.start_qd = Eigen::Vector2d(0, 0);
  p.goal.q = Eigen::Vector2d(1.2, 0);
  collision::Obstacle ball;
  ball.id = 1;
  ball.shape = collision::Shape::sphere(0.12);
  ball.pose.translation() = Eigen::Vector3d(0.1, 0, 1.9);
  p.obstacles.push_back(ball);
  return p;
}

/// The iiwa14 with the default 2 kg block (robots/README.md) at its flange.
inline std::shared_ptr<const dynamics::Model> iiwa_with_block() {
  return std::make_shared<const dynamics::Model>(dynamics::attach_box_payload(
      *load_robot("robots/iiwa14/iiwa14.urdf"), "iiwa_link_ee_kuka", 2.0, {0.1, 0.1, 0.1},
      Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05))));
}

/// The iiwa swings the block about its base axis, 2 s over `steps` intervals, without obstacles.
inline Problem iiwa_swing(int steps = 20) {
  Problem p;
  p.name = "iiwa_swing";
  p.model = iiwa_with_block();
  p.horizon = 2;
  p.steps = steps;
  Eigen::VectorXd qs(7), qg(7);
  qs << -0.9, 0.7, 0, -1.2, 0, 0.9, 0;
  qg << 0.9, 0.7, 0, -1.2, 0, 0.9, 0;
  p.start_q = qs;
  p.start_qd = Eigen::VectorXd::Zero(7);
  p.goal.q = qg;
  return p;
}

/// The tip's position ("ee") at joint configuration q as a position-only pose goal.
inline Goal tip_goal(const Problem& p, const Eigen::VectorXd& q) {
  dynamics::Data data(*p.model);
  dynamics::forward_kinematics(*p.model, data, q);
  Goal g;
  g.kind = Goal::Kind::kPose;
  g.frame = "ee";
  g.pose = dynamics::frame_pose(*p.model, data, p.model->frame_index("ee"));
  g.position_only = true;
  return g;
}

/// The RR arm over `steps` steps of 1 s in all, from (start_q, start_qd) to goal_q, no obstacles.
inline Problem rr_over_a_second(int steps, const Eigen::Vector2d& start_q,
                                const Eigen::Vector2d& start_qd, const Eigen::Vector2d& goal_q) {
  Problem problem;
  problem.model = load_robot("robots/rr/rr.urdf");
  problem.horizon = 1;
  problem.steps = steps;
  problem.start_q = start_q;
  problem.start_qd = start_qd;
  problem.goal.q = goal_q;
  return problem;
}

/// The RR arm holding still at q* = (0.5, −0.3) for 1 s over 10 steps, with its exact plan
/// (consistent, within limits, τ = gravity torque): a plan for validation tests to doctor.
struct StillRr {
  Problem problem;
  Plan plan;
  StillRr() {
    const Eigen::Vector2d q(0.5, -0.3);
    problem = rr_over_a_second(10, q, Eigen::Vector2d::Zero(), q);
    const int rows = problem.steps + 1;
    plan.q = q.transpose().replicate(rows, 1);
    plan.qd = Eigen::MatrixXd::Zero(rows, 2);
    plan.qdd = Eigen::MatrixXd::Zero(rows, 2);
    dynamics::Data d(*problem.model);
    const Eigen::VectorXd tau =
        dynamics::rnea(*problem.model, d, q, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero());
    plan.tau = tau.transpose().replicate(rows, 1);
    for (int k = 0; k < rows; ++k) plan.t.push_back(0.1 * k);
  }
};

// The RR arm from rest to rest over 3 intervals of 0.1 s with knot accelerations 0, A, −A, 0
// on joint 0, knots from the collocation: consistent, and joint 0's q̇ peaks between knots 1
// and 2 at 1.5 times its knot value hA/2 (0.3 vs 0.2 rad/s).
struct FastRr {
  Problem problem;
  Plan plan;
  FastRr() {
    const double h = 0.1, A = 4;
    problem.model = load_robot("robots/rr/rr.urdf");
    problem.horizon = 3 * h;
    problem.steps = 3;
    const double a[4] = {0, A, -A, 0};
    plan.q.setZero(4, 2);
    plan.qd.setZero(4, 2);
    plan.qdd.setZero(4, 2);
    plan.tau.setZero(4, 2);
    plan.q(0, 0) = 0.5;
    plan.q.col(1).setConstant(-0.3);
    for (int k = 0; k < 4; ++k) {
      plan.t.push_back(h * k);
      plan.qdd(k, 0) = a[k];
      if (k == 0) continue;
      plan.q(k, 0) = plan.q(k - 1, 0) + h * plan.qd(k - 1, 0) + h * h / 6 * (2 * a[k - 1] + a[k]);
      plan.qd(k, 0) = plan.qd(k - 1, 0) + h / 2 * (a[k - 1] + a[k]);
    }
    dynamics::Data d(*problem.model);
    for (int k = 0; k < 4; ++k) {
      plan.tau.row(k) = dynamics::rnea(*problem.model, d, plan.q.row(k).transpose(),
                                       plan.qd.row(k).transpose(), plan.qdd.row(k).transpose())
                            .transpose();
    }
    problem.start_q = plan.q.row(0).transpose();
    problem.start_qd = Eigen::Vector2d::Zero();
    problem.goal.q = plan.q.row(3).transpose();
  }
  // The same robot with joint 0's velocity limit set to `limit`.
  void limit_velocity(double limit) {
    auto m = std::make_shared<dynamics::Model>(*problem.model);
    m->bodies[0].limits.velocity = limit;
    problem.model = m;
  }
};

// The RR arm over one interval of 1 s whose elbow swings out and back: q̇ = ±4 rad/s at its
// ends, q̈ = −8 rad/s² throughout, q = 0 at both knots and 1 rad half-way. Consistent on the
// interpolant; τ left at zero.
struct SwingingRr {
  Problem problem;
  Plan plan;
  SwingingRr() {
    problem = rr_over_a_second(1, Eigen::Vector2d::Zero(), Eigen::Vector2d(0, 4),
                               Eigen::Vector2d::Zero());
    plan.q = Eigen::MatrixXd::Zero(2, 2);
    plan.qd = (Eigen::MatrixXd(2, 2) << 0, 4, 0, -4).finished();
    plan.qdd = (Eigen::MatrixXd(2, 2) << 0, -8, 0, -8).finished();
    plan.tau = Eigen::MatrixXd::Zero(2, 2);
    plan.t = {0, 1};
  }
};

// The RR arm over one interval of 1 s whose shoulder decelerates at kC = 5 rad/s² from
// kV0 = 2.25 rad/s and turns back at t = 0.45 s, at kTurn = 0.50625 rad: between the samples
// at 0.4 and 0.5 s (6.25 mrad below the turn at both). Elbow still; τ left at zero.
struct TurningRr {
  static constexpr double kC = 5, kV0 = 2.25, kTurn = kV0 * kV0 / (2 * kC);
  Problem problem;
  Plan plan;
  TurningRr() {
    problem = rr_over_a_second(1, Eigen::Vector2d::Zero(), Eigen::Vector2d(kV0, 0),
                               Eigen::Vector2d(kV0 - kC / 2, 0));
    plan.q = (Eigen::MatrixXd(2, 2) << 0, 0, kV0 - kC / 2, 0).finished();
    plan.qd = (Eigen::MatrixXd(2, 2) << kV0, 0, kV0 - kC, 0).finished();
    plan.qdd = (Eigen::MatrixXd(2, 2) << -kC, 0, -kC, 0).finished();
    plan.tau = Eigen::MatrixXd::Zero(2, 2);
    plan.t = {0, 1};
  }
};

}  // namespace kinograph::planning::testing
