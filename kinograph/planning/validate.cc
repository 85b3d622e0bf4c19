#include "kinograph/planning/validate.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kinograph/collision/collision_world.h"
#include "kinograph/collision/segment_checker.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/worker_pool.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/pose_error.h"
#include "kinograph/planning/interpolant.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {
namespace {

std::string fmt(const char* what, double value, double threshold) {
  std::ostringstream os;
  os << what << " " << value << " exceeds " << threshold;
  return os.str();
}

void add_failure(Validation& v, std::string why) { v.failures.push_back(std::move(why)); }

// How far x leaves [lo, hi] (0 inside).
double excess(double x, double lo, double hi) { return std::max({0.0, lo - x, x - hi}); }

// The trajectory's shape and numbers; false (with the failure) when nothing else can be checked.
bool check_shape(const Problem& problem, const Plan& plan, Validation& v) {
  if (!problem.model) {
    add_failure(v, "problem has no robot model");
    return false;
  }
  const dynamics::Model& model = *problem.model;
  const int n = model.nq(), N = problem.steps, rows = N + 1;
  if (N <= 0 || !(problem.horizon > 0)) {
    add_failure(v, "problem has no steps or a non-positive horizon");
    return false;
  }
  if (plan.q.rows() != rows || plan.qd.rows() != rows || plan.qdd.rows() != rows ||
      plan.tau.rows() != rows || plan.q.cols() != n || plan.qd.cols() != n ||
      plan.qdd.cols() != n || plan.tau.cols() != n) {
    std::ostringstream os;
    os << "plan has the wrong shape: expected " << rows << " x " << n << " for q, qd, qdd, tau";
    add_failure(v, os.str());
    return false;
  }
  if (!plan.q.allFinite() || !plan.qd.allFinite() || !plan.qdd.allFinite() ||
      !plan.tau.allFinite()) {
    add_failure(v, "plan holds NaN or infinite values");
    return false;
  }
  return true;
}

// The worst excess of one check, and where it is (for the failure line).
struct Worst {
  double amount = 0;
  int joint = -1;
  double t = 0;
  int interval = -1;  // ≥ 0 between knots interval and interval + 1, −1 at a knot
  void see(double x, int j, double time, int k) {
    if (x > amount) *this = {x, j, time, k};
  }
};

// "<what> <amount> exceeds <threshold>: joint '<name>' at t = <t> s (between knots k and k+1)".
std::string located(const char* what, const Worst& w, double threshold,
                    const dynamics::Model& model) {
  std::ostringstream os;
  os << fmt(what, w.amount, threshold);
  if (w.joint < 0) return os.str();
  os << ": joint '" << model.bodies[w.joint].joint_name << "' at t = " << w.t << " s";
  if (w.interval >= 0) os << " (between knots " << w.interval << " and " << w.interval + 1 << ")";
  return os.str();
}

// The limits of one state (at a knot, or a sample of the interpolant between knots).
struct StateWorst {
  Worst q, qd, qdd, tau, unactuated;
  void see(const dynamics::Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
           const Eigen::VectorXd* qdd, const Eigen::VectorXd& tau, double t, int k) {
    for (int j = 0; j < model.nq(); ++j) {
      const dynamics::JointLimits& lim = model.bodies[j].limits;
      this->q.see(excess(q[j], lim.lower, lim.upper), j, t, k);
      this->qd.see(excess(qd[j], -lim.velocity, lim.velocity), j, t, k);
      if (qdd != nullptr && std::isfinite(lim.acceleration)) {
        this->qdd.see(excess((*qdd)[j], -lim.acceleration, lim.acceleration), j, t, k);
      }
      if (model.bodies[j].actuated) {
        this->tau.see(excess(tau[j], -lim.effort, lim.effort), j, t, k);
      } else {
        unactuated.see(std::abs(tau[j]), j, t, k);
      }
    }
  }
};

// The plan with its own times, or a copy of it on the problem's grid when it has none.
const Plan& with_times(const Problem& problem, const Plan& plan, Plan& copy) {
  const int rows = problem.steps + 1;
  if (plan.t.size() == static_cast<size_t>(rows)) return plan;
  copy = plan;
  copy.t.resize(rows);
  for (int k = 0; k < rows; ++k) copy.t[k] = k * problem.dt();
  return copy;
}

// Where between two knots the interpolant is checked: fractions of the interval, the next
// knot (1) last. As dense as the planner's limit points, and at least interval_samples (the
// knot included).
std::vector<double> interval_fractions(const Problem& problem,
                                       const ValidationThresholds& thresholds) {
  const int samples = std::max(1, thresholds.interval_samples) > 1
                          ? limit_points(thresholds.interval_samples - 1, problem.dt()) + 1
                          : 1;
  std::vector<double> fractions;
  for (int i = 1; i < samples; ++i) fractions.push_back(static_cast<double>(i) / samples);
  fractions.push_back(1.0);
  return fractions;
}

// Whether actuated joint j's q or q̇ could reach a limit between interval k's samples (the
// knot, then `points`, evenly spaced): off the samples its cubic's q moves at most
// h²/8 · max |q̈| and its q̇ at most h²/8 · |q⃛| beyond them.
bool near_limit_between_samples(const dynamics::JointLimits& lim, const Plan& plan, int k, int j,
                                const std::vector<InterpolantPoint>& points, int samples) {
  const double dt = plan.t[k + 1] - plan.t[k], h = dt / samples;
  const double q_reach =
      h * h / 8 * std::max(std::abs(plan.qdd(k, j)), std::abs(plan.qdd(k + 1, j)));
  const double qd_reach = h * h / 8 * std::abs(plan.qdd(k + 1, j) - plan.qdd(k, j)) / dt;
  double lo = plan.q(k, j), hi = lo, fastest = std::abs(plan.qd(k, j));
  for (const InterpolantPoint& x : points) {
    lo = std::min(lo, x.q[j]);
    hi = std::max(hi, x.q[j]);
    fastest = std::max(fastest, std::abs(x.qd[j]));
  }
  return lo - q_reach < lim.lower || hi + q_reach > lim.upper || fastest + qd_reach > lim.velocity;
}

// Physics on the plan's interpolant (interpolant.h): inverse dynamics at the knots, the
// interpolant's continuity into every next knot (the collocation and, for unactuated joints,
// the shooting defect), and every limit at the knots and at `interval_samples` points of every
// interval.
void check_physics(const Problem& problem, const Plan& plan, const ValidationThresholds& thresholds,
                   dynamics::Data& data, Validation& v) {
  const dynamics::Model& model = *problem.model;
  const int N = problem.steps, rows = N + 1;
  Plan copy;
  const Plan* p = &with_times(problem, plan, copy);
  StateWorst knots, between;
  Worst position, velocity;
  for (int k = 0; k < rows; ++k) {
    const Eigen::VectorXd q = p->q.row(k).transpose(), qd = p->qd.row(k).transpose(),
                          qdd = p->qdd.row(k).transpose(), tau = p->tau.row(k).transpose();
    v.max_dynamics_residual = std::max(
        v.max_dynamics_residual, (tau - dynamics::rnea(model, data, q, qd, qdd)).cwiseAbs().maxCoeff());
    knots.see(model, q, qd, &qdd, tau, p->t[k], -1);
  }
  for (int k = 0; k < N; ++k) {
    if (!(p->t[k + 1] > p->t[k])) {
      add_failure(v, "plan times do not increase at t[" + std::to_string(k + 1) + "]");
      return;
    }
  }
  TrajectorySampler sampler(model, *p);
  const std::vector<double> fractions = interval_fractions(problem, thresholds);
  std::vector<InterpolantPoint> points;
  std::vector<double> turning;
  std::vector<InterpolantPoint> extremes;
  for (int k = 0; k < N; ++k) {
    sampler.interval(k, fractions, points);
    for (int i = 0; i + 1 < static_cast<int>(points.size()); ++i) {
      const InterpolantPoint& x = points[i];
      between.see(model, x.q, x.qd, &x.qdd, x.tau, p->t[k] + x.s, k);
    }
    // Between the samples an actuated joint's q and q̇ peak where its cubic turns: read there
    // too, where the samples come near a limit (unless only the knots are asked for).
    turning.clear();
    for (int j = 0; j < model.nq() && fractions.size() > 1; ++j) {
      if (!model.bodies[j].actuated) continue;
      if (near_limit_between_samples(model.bodies[j].limits, *p, k, j, points,
                                     static_cast<int>(fractions.size()))) {
        actuated_turning_times(p->qd(k, j), p->qdd(k, j), p->qdd(k + 1, j), p->t[k + 1] - p->t[k],
                               turning);
      }
    }
    if (!turning.empty()) {
      const double dt = p->t[k + 1] - p->t[k];
      for (double& s : turning) s /= dt;
      std::sort(turning.begin(), turning.end());
      sampler.interval(k, turning, extremes);
      for (const InterpolantPoint& x : extremes) {
        between.see(model, x.q, x.qd, &x.qdd, x.tau, p->t[k] + x.s, k);
      }
    }
    const InterpolantPoint& end = points.back();
    for (int j = 0; j < model.nq(); ++j) {
      position.see(std::abs(p->q(k + 1, j) - end.q[j]), j, p->t[k + 1], k);
      velocity.see(std::abs(p->qd(k + 1, j) - end.qd[j]), j, p->t[k + 1], k);
    }
  }
  v.max_position_consistency = position.amount;
  v.max_velocity_consistency = velocity.amount;
  v.max_q_violation = std::max(knots.q.amount, between.q.amount);
  v.max_qd_violation = std::max(knots.qd.amount, between.qd.amount);
  v.max_qdd_violation = std::max(knots.qdd.amount, between.qdd.amount);
  v.max_tau_violation = knots.tau.amount;
  v.max_unactuated_torque = knots.unactuated.amount;
  v.max_tau_violation_between = between.tau.amount;
  v.max_unactuated_torque_between = between.unactuated.amount;
  if (v.max_dynamics_residual > thresholds.dynamics)
    add_failure(
        v, fmt("dynamics residual |tau - ID| (N·m)", v.max_dynamics_residual, thresholds.dynamics));
  const auto report = [&](const char* what, const Worst& w, double threshold) {
    if (w.amount > threshold) add_failure(v, located(what, w, threshold, model));
  };
  report("position consistency (rad)", position, thresholds.position_consistency);
  report("velocity consistency (rad/s)", velocity, thresholds.velocity_consistency);
  const struct {
    const char* what;
    Worst StateWorst::*field;
    double threshold;
  } limits[] = {{"joint position limit violation (rad)", &StateWorst::q, thresholds.limit},
                {"joint velocity limit violation (rad/s)", &StateWorst::qd, thresholds.limit},
                {"joint acceleration limit violation (rad/s²)", &StateWorst::qdd, thresholds.limit},
                {"effort limit violation (N·m)", &StateWorst::tau, thresholds.limit},
                {"torque on an unactuated joint (N·m)", &StateWorst::unactuated,
                 thresholds.unactuated_torque}};
  for (const auto& l : limits) {
    // One line per check: the worse of the knots and the samples between them.
    const Worst& a = knots.*l.field;
    const Worst& b = between.*l.field;
    report(l.what, a.amount >= b.amount ? a : b, l.threshold);
  }
}

// The start state and the goal (at rest), naming the joint or frame that misses.
void check_start_and_goal(const Problem& problem, const Plan& plan,
                          const ValidationThresholds& thresholds, dynamics::Data& data,
                          Validation& v) {
  const dynamics::Model& model = *problem.model;
  const int n = model.nq(), N = problem.steps;
  const double t_end = plan.t.size() == static_cast<size_t>(N + 1) ? plan.t[N] : problem.horizon;
  std::string start_worst;
  const auto start_row = [&](const Eigen::MatrixXd& x, const Eigen::VectorXd& target, int d) {
    for (int j = 0; j < n; ++j) {
      const double e = std::abs(x(0, j) - target[j]);
      if (e <= v.start_error) continue;
      v.start_error = e;
      start_worst = joint_label(model, j) + (d == 0 ? " position " : " velocity ") +
                    number(x(0, j)) + " " + joint_unit(model, j, d) + " instead of " +
                    number(target[j]);
    }
  };
  if (problem.start_q.size() == n) start_row(plan.q, problem.start_q, 0);
  if (problem.start_qd.size() == n) start_row(plan.qd, problem.start_qd, 1);
  if (v.start_error > thresholds.start)
    add_failure(v, fmt("start state error", v.start_error, thresholds.start) + " (" + start_worst +
                       " at t = 0)");
  std::string final_worst;
  for (int j = 0; j < n; ++j) {
    for (int d = 1; d <= 2; ++d) {
      const double x = d == 1 ? plan.qd(N, j) : plan.qdd(N, j);
      if (std::abs(x) <= v.final_velocity) continue;
      v.final_velocity = std::abs(x);
      final_worst = joint_label(model, j) + (d == 1 ? " velocity " : " acceleration ") + number(x) +
                    " " + joint_unit(model, j, d);
    }
  }
  if (v.final_velocity > thresholds.final_velocity)
    add_failure(v, fmt("final velocity/acceleration (goal is at rest)", v.final_velocity,
                       thresholds.final_velocity) +
                       " (" + final_worst + " at " + at_time(t_end) + ")");
  const Eigen::VectorXd q_final = plan.q.row(N).transpose();
  // A goal's own tolerance (> 0) replaces the default threshold; the worst error relative to
  // its tolerance is the one reported.
  const auto tolerance_or_default = [&](double t) { return t > 0 ? t : thresholds.goal; };
  std::string goal_worst;
  double worst_ratio = 0, worst_error = 0, worst_tolerance = thresholds.goal;
  const auto weigh = [&](double error, double tolerance, std::string what) {
    if (error / tolerance <= worst_ratio) return;
    worst_ratio = error / tolerance;
    worst_error = error;
    worst_tolerance = tolerance;
    goal_worst = std::move(what);
  };
  const Goal& goal = problem.goal;
  if (goal.kind == Goal::Kind::kJoint) {
    if (goal.q.size() != n) {
      add_failure(v, "joint goal has the wrong size");
    } else if (goal.joint_tolerance.size() != 0 && goal.joint_tolerance.size() != n) {
      add_failure(v, "joint goal tolerance has the wrong size");
    } else {
      for (int j = 0; j < n; ++j) {
        const double e = std::abs(q_final[j] - goal.q[j]);
        v.goal_error = std::max(v.goal_error, e);
        weigh(e, tolerance_or_default(goal.joint_tolerance.size() ? goal.joint_tolerance[j] : 0),
              joint_label(model, j) + " ends at " + number(q_final[j]) + " " +
                  joint_unit(model, j, 0) + ", its goal is " + number(goal.q[j]));
      }
    }
  } else {
    int frame = -1;
    try {
      frame = model.frame_index(goal.frame);
    } catch (const std::out_of_range&) {
      add_failure(v, "goal frame '" + goal.frame + "' is not in the model");
    }
    if (frame >= 0) {
      dynamics::forward_kinematics(model, data, q_final);
      const PoseError e = pose_error(dynamics::frame_pose(model, data, frame), goal.pose);
      v.goal_error = goal.position_only ? e.position : std::max(e.position, e.rotation);
      const std::string where = "frame '" + goal.frame + "' ends ";
      weigh(e.position, tolerance_or_default(goal.position_tolerance),
            where + number(e.position) + " m from its goal position");
      if (!goal.position_only) {
        weigh(e.rotation, tolerance_or_default(goal.orientation_tolerance),
              where + number(e.rotation) + " rad from its goal orientation");
      }
    }
  }
  if (worst_ratio > 1)
    add_failure(v, fmt("goal error", worst_error, worst_tolerance) + " (" + goal_worst + " at " +
                       at_time(t_end) + ")");
}

// Task constraints on the interpolant, at the knots and where the physics is checked between
// them, naming the frame and the time of the worst point.
void check_tasks(const Problem& problem, const Plan& plan, const ValidationThresholds& thresholds,
                 dynamics::Data& data, Validation& v) {
  if (problem.task_constraints.empty()) return;
  const dynamics::Model& model = *problem.model;
  const int N = problem.steps;
  Plan copy;
  const Plan& p = with_times(problem, plan, copy);
  for (int k = 0; k < N; ++k) {
    if (!(p.t[k + 1] > p.t[k])) return;  // the physics reports the times
  }
  // The configurations checked and their times: every knot, then the points between.
  std::vector<Eigen::VectorXd> q;
  std::vector<double> t;
  for (int k = 0; k <= N; ++k) {
    q.push_back(p.q.row(k).transpose());
    t.push_back(p.t[k]);
  }
  TrajectorySampler sampler(model, p);
  std::vector<double> fractions = interval_fractions(problem, thresholds);
  fractions.pop_back();  // the next knot is checked as a knot
  std::vector<InterpolantPoint> points;
  for (int k = 0; k < N && !fractions.empty(); ++k) {
    sampler.interval(k, fractions, points);
    for (const InterpolantPoint& x : points) {
      q.push_back(x.q);
      t.push_back(p.t[k] + x.s);
    }
  }
  for (const TaskConstraint& task : problem.task_constraints) {
    int frame = -1;
    try {
      frame = model.frame_index(task.frame);
    } catch (const std::out_of_range&) {
      add_failure(v, "task-constraint frame '" + task.frame + "' is not in the model");
      continue;
    }
    double worst = 0;
    size_t worst_at = 0;
    for (size_t i = 0; i < q.size(); ++i) {
      dynamics::forward_kinematics(model, data, q[i]);
      const PoseError e = pose_error(dynamics::frame_pose(model, data, frame), task.target);
      const double err = task.orientation_only ? e.rotation : std::max(e.rotation, e.position);
      if (err > worst) {
        worst = err;
        worst_at = i;
      }
    }
    v.max_task_error = std::max(v.max_task_error, worst);
    if (worst > task.tolerance)
      add_failure(v,
                  fmt(("task constraint on '" + task.frame + "'").c_str(), worst, task.tolerance) +
                      " at " + at_time(t[worst_at]));
  }
}

// The collision walk is cut at knots into this many pieces (fewer for short plans), each
// walked on its own, so that the pieces and the physics check share the cores. The number is
// fixed, never the thread count's: a plan's figures are the same on any machine.
constexpr int kCollisionPieces = 4;

// Clearance (obstacles, the floor, self pairs) along the plan's interpolant: its states at
// `collision_samples` points of every interval, and between two of them the straight segment
// widened by how far the interpolant strays from it, walked by conservative advancement
// (stretches far from everything cost one query; near something the samples are as dense as the
// segment checker's sweep step). walk(p) samples and checks piece p (on any thread: each piece
// has its own world and interpolant), report() turns the pieces' results into figures and
// failures.
class CollisionWalk {
 public:
  // With `verdict_only` each piece stops at its first sample that breaks the clearance.
  CollisionWalk(const Problem& problem, const Plan& plan, const ValidationThresholds& thresholds,
                bool verdict_only)
      : problem_(problem),
        plan_(plan),
        clearance_(thresholds.min_clearance),
        verdict_only_(verdict_only),
        sub_(std::max(1, thresholds.collision_samples)),
        timed_(plan.t.size() == static_cast<size_t>(problem.steps + 1)) {
    const int N = problem.steps, pieces = std::clamp(N, 1, kCollisionPieces);
    for (int p = 0; p <= pieces; ++p) first_knot_.push_back(p * N / pieces);
    results_.resize(pieces);
    errors_.resize(pieces);
  }

  int pieces() const { return static_cast<int>(results_.size()); }

  // Walks piece p, knots first_knot_[p] … first_knot_[p + 1], with its share of the walk's
  // budgets.
  void walk(int p) {
    std::unique_ptr<collision::CollisionWorld> world;
    try {
      world = clearance_world(problem_);
    } catch (const std::invalid_argument& e) {
      errors_[p] = e.what();
      return;
    }
    collision::SegmentCheckOptions options;
    options.max_path_samples = std::max(1, options.max_path_samples / pieces());
    options.max_path_sweep /= pieces();
    if (verdict_only_) options.stop_below = clearance_;
    collision::SegmentChecker checker(*problem_.model, options);
    dynamics::Data data(*problem_.model);
    Eigen::MatrixXd path, stray;
    std::vector<double> times;
    sample(first_knot_[p], first_knot_[p + 1], path, stray, times);
    results_[p] = checker.check_path(*world, data, path, times, clearance_, stray);
    const int r0 = first_knot_[p] * sub_;
    results_[p].segment += r0;
    results_[p].stopped_segment += r0;
  }

  // The smallest clearance over the pieces and the failures: a world that cannot be built,
  // the first piece whose walk stopped, and the closest approach when it is too close.
  void report(Validation& v) const {
    for (const std::string& e : errors_) {
      if (e.empty()) continue;
      add_failure(v, e);
      return;  // every piece builds the same world
    }
    const collision::PathCheckResult* closest = nullptr;
    for (const collision::PathCheckResult& r : results_) {
      if (closest == nullptr || r.min_distance < closest->min_distance) closest = &r;
    }
    v.min_clearance = std::min(v.min_clearance, closest->min_distance);
    for (const collision::PathCheckResult& r : results_) {
      if (r.complete) continue;
      std::ostringstream os;
      os << "collision: not checked after t = " << time_at(r.stopped_segment, r.stopped_s)
         << " s: the path sweeps too far (" << r.swept << " m in " << r.samples
         << " collision queries; q or q̇ far beyond what the robot can move)";
      add_failure(v, os.str());
      break;
    }
    if (closest->min_distance < clearance_) {
      std::ostringstream os;
      os << "collision: " << describe_pair(*problem_.model, closest->closest);
      if (closest->min_distance < 0) {
        os << " overlap by " << -closest->min_distance << " m";
      } else {
        os << " are " << closest->min_distance << " m apart";
      }
      os << " at t = " << time_at(closest->segment, closest->s) << " s (required clearance "
         << clearance_ << " m)";
      add_failure(v, os.str());
    }
  }

 private:
  double knot_time(int k) const { return timed_ ? plan_.t[k] : k * problem_.dt(); }

  // The time a fraction s along path segment r (sub_ segments an interval).
  double time_at(int r, double s) const {
    const int k = std::min(r / sub_, problem_.steps);
    if (k == problem_.steps) return knot_time(k);
    const double dt = knot_time(k + 1) - knot_time(k);
    return knot_time(k) + dt * (r % sub_ + s) / sub_;
  }

  // The path of knots k0 … k1: the interpolant at sub_ points an interval (rows, at `times`),
  // and per segment and joint how far the interpolant strays from the straight segment.
  void sample(int k0, int k1, Eigen::MatrixXd& path, Eigen::MatrixXd& stray,
              std::vector<double>& times) const {
    const dynamics::Model& model = *problem_.model;
    const int n = model.nq(), sub = sub_;
    path.resize((k1 - k0) * sub + 1, n);
    stray.setZero((k1 - k0) * sub, n);
    times.resize(path.rows());
    IntervalInterpolant interpolant(model);
    InterpolantPoint point;
    Eigen::MatrixXd qdd(sub + 1, n);  // |q̈| at the interval's samples and its end
    for (int k = k0; k < k1; ++k) {
      const double dt = knot_time(k + 1) - knot_time(k);
      const int first = (k - k0) * sub;
      for (int i = 0; i < sub; ++i) times[first + i] = time_at(k * sub + i, 0);
      if (!(dt > 0) || !std::isfinite(dt)) {  // the physics reports the times; nothing moves
        path.middleRows(first, sub) = plan_.q.row(k).replicate(sub, 1);
        continue;
      }
      interpolant.start(plan_.q.row(k).transpose(), plan_.qd.row(k).transpose(),
                        plan_.qdd.row(k).transpose(), plan_.qdd.row(k + 1).transpose(), dt, false);
      for (int i = 0; i <= sub; ++i) {
        interpolant.at(dt * i / sub, false, point, /*with_tau=*/false);
        if (i < sub) path.row(first + i) = point.q.transpose();
        qdd.row(i) = point.qdd.cwiseAbs().transpose();
      }
      // Off its samples a joint strays from the chord by at most h²/8 · max |q̈| between them
      // (linear on an actuated joint's cubic; an unactuated joint takes its interval's largest),
      // and the last chord ends at the next knot, not where the interpolant arrives.
      const double h = dt / sub;
      for (int j = 0; j < n; ++j) {
        const double interval_max = qdd.col(j).maxCoeff();
        for (int i = 0; i < sub; ++i) {
          const double a =
              model.bodies[j].actuated ? std::max(qdd(i, j), qdd(i + 1, j)) : interval_max;
          double e = h * h / 8 * a;
          if (i + 1 == sub) e += std::abs(point.q[j] - plan_.q(k + 1, j));
          // Non-finite only where the path itself is: the walk stops there and says so.
          stray(first + i, j) = std::isfinite(e) ? e : 0.0;
        }
      }
    }
    path.row(path.rows() - 1) = plan_.q.row(k1);
    times.back() = knot_time(k1);
  }

  const Problem& problem_;
  const Plan& plan_;
  double clearance_;
  bool verdict_only_;
  int sub_;                      // path rows an interval
  bool timed_;                   // the plan has its own times; else the problem's grid
  std::vector<int> first_knot_;  // piece p walks knots first_knot_[p] … first_knot_[p + 1]
  std::vector<collision::PathCheckResult> results_;
  std::vector<std::string> errors_;  // a world that could not be built, per piece
};

}  // namespace

Validation validate(const Problem& problem, const Plan& plan,
                    const ValidationThresholds& thresholds, bool verdict_only) {
  Validation v;
  if (!check_shape(problem, plan, v)) return v;
  dynamics::Data data(*problem.model);
  std::optional<CollisionWalk> walk;
  if (has_clearance_checks(problem)) walk.emplace(problem, plan, thresholds, verdict_only);
  // Item 0 is the physics, item p + 1 the collision walk's piece p; each writes only its own.
  std::vector<int> items(1 + (walk ? walk->pieces() : 0));
  std::iota(items.begin(), items.end(), 0);
  auto one = [&](int item, int) {
    if (item == 0) {
      check_physics(problem, plan, thresholds, data, v);
    } else {
      walk->walk(item - 1);
    }
  };
  graph::share_out(static_cast<int>(items.size()), {}, items, one, 1);
  check_start_and_goal(problem, plan, thresholds, data, v);
  check_tasks(problem, plan, thresholds, data, v);
  // A caller that only needs the verdict has no use for the clearance once another check failed.
  if (walk && !(verdict_only && !v.failures.empty())) walk->report(v);
  v.valid = v.failures.empty();
  return v;
}

}  // namespace kinograph::planning
