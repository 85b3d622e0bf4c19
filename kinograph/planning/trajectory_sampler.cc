#include "kinograph/planning/trajectory_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kinograph::planning {

TrajectorySampler::TrajectorySampler(const dynamics::Model& model, const Plan& plan)
    : plan_(plan), interpolant_(model) {
  const Eigen::Index n = model.nq(), rows = static_cast<Eigen::Index>(plan.t.size());
  if (rows < 2) throw std::invalid_argument("plan: sampling needs at least two knots with times");
  const auto check = [&](const Eigen::MatrixXd& m, const char* name) {
    if (m.rows() != rows || m.cols() != n) {
      throw std::invalid_argument("plan: " + std::string(name) + " must be " +
                                  std::to_string(rows) + " x " + std::to_string(n) +
                                  " (knots x joints of '" + model.name + "')");
    }
  };
  check(plan.q, "q");
  check(plan.qd, "qd");
  check(plan.qdd, "qdd");
  for (size_t k = 1; k < plan.t.size(); ++k) {
    if (!(plan.t[k] > plan.t[k - 1])) {
      throw std::invalid_argument("plan: t[" + std::to_string(k) + "] does not increase");
    }
  }
}

void TrajectorySampler::interval(int k, const std::vector<double>& fractions,
                                 std::vector<InterpolantPoint>& out) {
  if (k < 0 || k >= intervals()) {
    throw std::invalid_argument("plan: no interval " + std::to_string(k));
  }
  const double dt = interval_length(k);
  times_.resize(fractions.size());
  for (size_t i = 0; i < fractions.size(); ++i) times_[i] = std::clamp(fractions[i], 0.0, 1.0) * dt;
  interpolant_.evaluate(plan_.q.row(k).transpose(), plan_.qd.row(k).transpose(),
                        plan_.qdd.row(k).transpose(), plan_.qdd.row(k + 1).transpose(), dt, times_,
                        false, out);
}

InterpolantPoint TrajectorySampler::interval_end(int k) {
  interval(k, {1.0}, points_);
  return points_[0];
}

InterpolantPoint TrajectorySampler::at(double t) {
  const int N = intervals();
  if (!(t < plan_.t[N])) return interval_end(N - 1);
  const auto upper = std::upper_bound(plan_.t.begin(), plan_.t.end(), t);
  const int k = std::max(0, static_cast<int>(upper - plan_.t.begin()) - 1);
  interval(k, {std::max(0.0, (t - plan_.t[k]) / interval_length(k))}, points_);
  return points_[0];
}

SampledPath sample_plan(const dynamics::Model& model, const Plan& plan, int per_interval) {
  if (per_interval < 1) throw std::invalid_argument("sample_plan: per_interval must be >= 1");
  TrajectorySampler sampler(model, plan);
  const int N = sampler.intervals(), n = model.nq(), rows = N * per_interval + 1;
  SampledPath path;
  path.t.resize(rows);
  path.q.resize(rows, n);
  path.qd.resize(rows, n);
  path.qdd.resize(rows, n);
  path.tau.resize(rows, n);
  std::vector<double> fractions(per_interval);
  for (int i = 0; i < per_interval; ++i) fractions[i] = static_cast<double>(i) / per_interval;
  std::vector<InterpolantPoint> points;
  const auto put = [&](int row, double t, const InterpolantPoint& p) {
    path.t[row] = t;
    path.q.row(row) = p.q.transpose();
    path.qd.row(row) = p.qd.transpose();
    path.qdd.row(row) = p.qdd.transpose();
    path.tau.row(row) = p.tau.transpose();
  };
  for (int k = 0; k < N; ++k) {
    sampler.interval(k, fractions, points);
    for (int i = 0; i < per_interval; ++i) {
      put(k * per_interval + i, plan.t[k] + fractions[i] * sampler.interval_length(k), points[i]);
    }
  }
  put(rows - 1, plan.t[N], sampler.interval_end(N - 1));
  return path;
}

}  // namespace kinograph::planning
