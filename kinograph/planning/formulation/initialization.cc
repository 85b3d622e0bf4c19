#include "kinograph/planning/formulation/initialization.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/worker_local.h"

namespace kinograph::planning {

std::optional<Eigen::VectorXd> goal_configuration(const Problem& problem) {
  const dynamics::Model& model = *problem.model;
  const int n = model.nq();
  if (problem.goal.kind == Goal::Kind::kJoint) return problem.goal.q;
  int frame = -1;
  try {
    frame = model.frame_index(problem.goal.frame);
  } catch (const std::out_of_range&) {
    return std::nullopt;
  }
  const int body = model.frames[frame].body;
  const bool orient = !problem.goal.position_only;
  dynamics::Data data(model);
  Eigen::VectorXd q = problem.start_q;
  Eigen::Matrix<double, 6, Eigen::Dynamic> J6(6, n);
  Eigen::Matrix3Xd J3(3, n);
  const Eigen::Isometry3d& target = problem.goal.pose;
  double lambda = 1e-2;
  for (int it = 0; it < 200 && body >= 0; ++it) {
    dynamics::forward_kinematics(model, data, q);
    const Eigen::Isometry3d T = dynamics::frame_pose(model, data, frame);
    // Error twist: world-frame rotation vector (small-angle from R R*ᵀ) and position error.
    const Eigen::AngleAxisd aa(T.linear() * target.linear().transpose());
    Eigen::VectorXd e(orient ? 6 : 3);
    Eigen::MatrixXd J(orient ? 6 : 3, n);
    dynamics::point_jacobian(model, data, body, T.translation(), J3);
    if (orient) {
      dynamics::space_jacobian(model, data, body, J6);
      e << aa.angle() * aa.axis(), T.translation() - target.translation();
      J << J6.topRows<3>(), J3;
    } else {
      e = T.translation() - target.translation();
      J = J3;
    }
    if (e.norm() < 1e-9) break;
    const Eigen::MatrixXd A =
        J * J.transpose() + lambda * Eigen::MatrixXd::Identity(J.rows(), J.rows());
    Eigen::VectorXd dq = -J.transpose() * A.ldlt().solve(e);
    const double step = dq.cwiseAbs().maxCoeff();
    if (step > 0.3) dq *= 0.3 / step;
    q += dq;
    for (int j = 0; j < n; ++j) {
      const auto& l = model.bodies[j].limits;
      q[j] = std::clamp(q[j], l.lower, l.upper);
    }
  }
  return q;
}

Trajectory straight_line(const Problem& problem, const Eigen::VectorXd& q_goal) {
  const int N = problem.steps, n = static_cast<int>(q_goal.size());
  const double T = problem.horizon;
  Trajectory tr;
  tr.q.resize(N + 1, n);
  tr.qd.resize(N + 1, n);
  tr.qdd.resize(N + 1, n);
  const Eigen::VectorXd q0 = problem.start_q;
  const Eigen::VectorXd v0 =
      problem.start_qd.size() == n ? problem.start_qd : Eigen::VectorXd::Zero(n);
  // Quintic with q(0) = q0, q̇(0) = v0, q̈(0) = 0, q(T) = q_goal, q̇(T) = q̈(T) = 0, per joint:
  // q = q0 + v0 t + c3 t³ + c4 t⁴ + c5 t⁵.
  const Eigen::VectorXd d = q_goal - q0 - v0 * T;
  // (c3, c4, c5) from the end conditions q(T) − q0 − v0 T = d, q̇(T) = 0, q̈(T) = 0.
  Eigen::Matrix3d A;
  A << std::pow(T, 3), std::pow(T, 4), std::pow(T, 5), 3 * T * T, 4 * std::pow(T, 3),
      5 * std::pow(T, 4), 6 * T, 12 * T * T, 20 * std::pow(T, 3);
  const Eigen::Matrix3d Ainv = A.inverse();
  Eigen::MatrixXd C(3, n);
  for (int j = 0; j < n; ++j) C.col(j) = Ainv * Eigen::Vector3d(d[j], -v0[j], 0);
  for (int k = 0; k <= N; ++k) {
    const double t = T * k / N;
    const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
    for (int j = 0; j < n; ++j) {
      tr.q(k, j) = q0[j] + v0[j] * t + C(0, j) * t3 + C(1, j) * t4 + C(2, j) * t5;
      tr.qd(k, j) = v0[j] + 3 * C(0, j) * t2 + 4 * C(1, j) * t3 + 5 * C(2, j) * t4;
      tr.qdd(k, j) = 6 * C(0, j) * t + 12 * C(1, j) * t2 + 20 * C(2, j) * t3;
    }
  }
  return tr;
}

Trajectory warm_start(const Problem& problem, const Plan& previous) {
  const int n = problem.model->nq(), N = problem.steps;
  const int M = static_cast<int>(previous.q.rows());
  if (previous.q.cols() != n || M < 2 || previous.qd.rows() != M || previous.qdd.rows() != M) {
    throw std::invalid_argument("warm start plan does not match the problem's robot");
  }
  Trajectory tr;
  tr.q.resize(N + 1, n);
  tr.qd.resize(N + 1, n);
  tr.qdd.resize(N + 1, n);
  for (int k = 0; k <= N; ++k) {
    // Fraction of the previous plan's horizon (plans are resampled by normalized time).
    const double u = static_cast<double>(k) / N * (M - 1);
    const int i = std::min(static_cast<int>(std::floor(u)), M - 2);
    const double s = u - i;
    tr.q.row(k) = (1 - s) * previous.q.row(i) + s * previous.q.row(i + 1);
    tr.qd.row(k) = (1 - s) * previous.qd.row(i) + s * previous.qd.row(i + 1);
    tr.qdd.row(k) = (1 - s) * previous.qdd.row(i) + s * previous.qdd.row(i + 1);
  }
  tr.q.row(0) = problem.start_q.transpose();
  if (problem.start_qd.size() == n) tr.qd.row(0) = problem.start_qd.transpose();
  return tr;
}

Trajectory segment_trajectory(const Problem& problem, const std::vector<Eigen::VectorXd>& waypoints,
                              const std::vector<int>& steps) {
  const int n = problem.model->nq(), N = problem.steps;
  int total = 0;
  for (int s : steps) {
    if (s < 1) throw std::invalid_argument("segment_trajectory: a segment without steps");
    total += s;
  }
  if (waypoints.size() < 2 || steps.size() + 1 != waypoints.size() || total != N) {
    throw std::invalid_argument("segment_trajectory: waypoints and steps do not match");
  }
  Trajectory tr;
  tr.q.resize(N + 1, n);
  tr.qd.resize(N + 1, n);
  tr.qdd.resize(N + 1, n);
  int k = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    Problem part = problem;
    part.steps = steps[i];
    part.horizon = problem.dt() * steps[i];
    part.start_q = waypoints[i];
    if (i > 0) part.start_qd = Eigen::VectorXd::Zero(n);
    const Trajectory t = straight_line(part, waypoints[i + 1]);
    const int skip = i == 0 ? 0 : 1;  // the segment's first state is the previous one's last
    tr.q.middleRows(k, steps[i] + 1 - skip) = t.q.bottomRows(steps[i] + 1 - skip);
    tr.qd.middleRows(k, steps[i] + 1 - skip) = t.qd.bottomRows(steps[i] + 1 - skip);
    tr.qdd.middleRows(k, steps[i] + 1 - skip) = t.qdd.bottomRows(steps[i] + 1 - skip);
    k += steps[i] + 1 - skip;
  }
  return tr;
}

Trajectory path_trajectory(const Problem& problem, const std::vector<Eigen::VectorXd>& waypoints) {
  const int segments = static_cast<int>(waypoints.size()) - 1;
  if (segments < 1 || 2 * segments > problem.steps) {
    throw std::invalid_argument("path_trajectory: " + std::to_string(segments) +
                                " segments do not fit " + std::to_string(problem.steps) + " steps");
  }
  const dynamics::Model& model = *problem.model;
  std::vector<double> need(segments, 0.0);
  double sum = 0;
  for (int i = 0; i < segments; ++i) {
    for (int j = 0; j < model.nq(); ++j) {
      const double v = model.bodies[j].limits.velocity;
      const double d = std::abs(waypoints[i + 1][j] - waypoints[i][j]);
      need[i] = std::max(need[i], std::isfinite(v) && v > 0 ? d / v : d);
    }
    need[i] += 1e-9;  // a segment that does not move still gets its share of the minimum
    sum += need[i];
  }
  // Two steps each, the rest by largest remainder of the proportional share.
  std::vector<int> steps(segments, 2);
  const int spare = problem.steps - 2 * segments;
  std::vector<std::pair<double, int>> remainder;
  int given = 0;
  for (int i = 0; i < segments; ++i) {
    const double share = spare * need[i] / sum;
    steps[i] += static_cast<int>(std::floor(share));
    given += static_cast<int>(std::floor(share));
    remainder.push_back({share - std::floor(share), i});
  }
  std::stable_sort(remainder.begin(), remainder.end(),
                   [](const auto& x, const auto& y) { return x.first > y.first; });
  for (int r = 0; r < spare - given; ++r) ++steps[remainder[r].second];
  return segment_trajectory(problem, waypoints, steps);
}

Trajectory via_point(const Problem& problem, const Eigen::VectorXd& q_via,
                     const Eigen::VectorXd& q_goal) {
  const int N = problem.steps;
  if (N < 2) return straight_line(problem, q_goal);
  return segment_trajectory(problem, {problem.start_q, q_via, q_goal}, {N / 2, N - N / 2});
}

namespace {
// Smallest clearance along a → b, travelled from time t0 to t1 (for moving obstacles), with a
// prepared world and workspace; a clearance above `cap` counts as `cap`, which saves finding
// the closest pair wherever none is within it. The ends come first, then the rest coarse to
// fine (middle, quarters, …), so a segment through an obstacle shows it after a few samples;
// the walk gives up as soon as `give_up(smallest so far)` says so, returning that smallest. The
// minimum does not depend on the order.
template <class GiveUp>
double clearance_along(const dynamics::Model& model, collision::CollisionWorld& world,
                       dynamics::Data& data, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                       double t0, double t1, int samples, double cap, GiveUp give_up) {
  double worst = std::numeric_limits<double>::infinity();
  const auto visit = [&](int i) {
    graph::throw_if_cancelled();  // the detour ranking walks many segments before any solve
    const double s = static_cast<double>(i) / samples, t = (1 - s) * t0 + s * t1;
    dynamics::forward_kinematics(model, data, (1 - s) * a + s * b);
    worst = std::min(worst, std::isfinite(cap) && !world.any_within(data, t, cap)
                                ? cap
                                : world.closest(data, t).distance);
    return give_up(std::min(worst, cap));
  };
  if (visit(0) || visit(samples)) return std::min(worst, cap);
  int top = 1;
  while (2 * top < samples) top *= 2;
  for (int stride = top; stride >= 1; stride /= 2) {
    for (int i = stride; i < samples; i += 2 * stride) {
      if (visit(i)) return std::min(worst, cap);
    }
  }
  return std::min(worst, cap);
}
}  // namespace

double segment_clearance(const Problem& problem, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                         int samples) {
  if (problem.obstacles.empty()) return std::numeric_limits<double>::infinity();
  collision::CollisionWorld world(*problem.model);
  for (const auto& o : problem.obstacles) world.add_obstacle(o);
  dynamics::Data data(*problem.model);
  return clearance_along(*problem.model, world, data, a, b, 0, problem.horizon,
                         std::max(1, samples), std::numeric_limits<double>::infinity(),
                         [](double) { return false; });
}

std::vector<Detour> detour_candidates(const Problem& problem, const Eigen::VectorXd& q_goal,
                                      const DetourOptions& options, int best) {
  if (problem.obstacles.empty() || options.candidates <= 0 || best == 0) return {};
  const dynamics::Model& model = *problem.model;
  const int n = model.nq();
  // Every via point is drawn first, in the seed's order; their paths are then checked on the
  // process's workers (graph/worker_pool.h), each with its own world and workspace, so the
  // ranking does not depend on which worker checked which.
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u(-options.spread, options.spread);
  const Eigen::VectorXd mid = 0.5 * (problem.start_q + q_goal);
  std::vector<Eigen::VectorXd> vias(static_cast<size_t>(options.candidates), mid);
  for (Eigen::VectorXd& q : vias) {
    for (int j = 0; j < n; ++j) {
      const auto& l = model.bodies[j].limits;
      q[j] = std::clamp(q[j] + u(rng), l.lower, l.upper);
    }
  }
  const size_t keep = best < 0 ? vias.size() : std::min(vias.size(), static_cast<size_t>(best));
  struct Probe {
    collision::CollisionWorld world;
    dynamics::Data data;
  };
  graph::WorkerLocal<Probe> probes([&problem] {
    auto p = std::make_unique<Probe>(Probe{collision::CollisionWorld(*problem.model),
                                           dynamics::Data(*problem.model)});
    for (const auto& o : problem.obstacles) p->world.add_obstacle(o);
    return p;
  });
  const double eps = problem.objectives.collision_epsilon;
  const int samples = std::max(1, options.samples);
  const double T = problem.horizon, half = problem.dt() * (problem.steps / 2);
  struct Candidate {
    double score = -std::numeric_limits<double>::infinity();
    Detour detour;
    bool ranked = false;  // checked to the end (not given up)
  };
  std::vector<Candidate> ranked(vias.size());
  // The keep-th best score of the candidates checked to the end so far (−∞ until there are
  // keep of them). A candidate whose score, which only falls as its samples are checked,
  // drops below it cannot be among the kept: its check stops there. So every candidate that
  // a full check would keep is checked to the end, with the same score, whatever the order.
  std::mutex kept_mutex;
  std::vector<double> kept_scores;  // descending, at most keep
  std::atomic<double> bar{-std::numeric_limits<double>::infinity()};
  auto check = [&](int c, int) {
    Probe& p = probes.local();
    const Eigen::VectorXd& q = vias[static_cast<size_t>(c)];
    // Clearance capped at ε (anything clearer is as good), then a small preference for short
    // detours, so the ranking is: collision-free first, then by joint-space length.
    const double length = (q - problem.start_q).norm() + (q_goal - q).norm();
    double c1 = eps;
    const auto below_bar = [&](double clearance) {
      return std::min(c1, clearance) - 1e-3 * length < bar.load(std::memory_order_relaxed);
    };
    c1 = clearance_along(model, p.world, p.data, problem.start_q, q, 0, half, samples, eps,
                         below_bar);
    if (below_bar(c1)) return;
    const double c2 =
        clearance_along(model, p.world, p.data, q, q_goal, half, T, samples, eps, below_bar);
    if (below_bar(c2)) return;
    const double score = std::min(c1, c2) - 1e-3 * length;
    ranked[static_cast<size_t>(c)] = {score, Detour{q, std::min(c1, c2)}, true};
    const std::lock_guard<std::mutex> lock(kept_mutex);
    kept_scores.insert(std::upper_bound(kept_scores.begin(), kept_scores.end(), score,
                                        std::greater<double>()),
                       score);
    if (kept_scores.size() > keep) kept_scores.pop_back();
    if (kept_scores.size() == keep) bar.store(kept_scores.back(), std::memory_order_relaxed);
  };
  std::vector<int> items(vias.size());
  std::iota(items.begin(), items.end(), 0);
  graph::share_out(graph::kMaxWorkers, {}, items, check, 1);
  std::stable_sort(ranked.begin(), ranked.end(), [](const Candidate& a, const Candidate& b) {
    return a.ranked != b.ranked ? a.ranked : a.score > b.score;
  });
  std::vector<Detour> out;
  for (size_t i = 0; i < keep && ranked[i].ranked; ++i) out.push_back(std::move(ranked[i].detour));
  return out;
}

}  // namespace kinograph::planning
