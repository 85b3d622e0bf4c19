#include "kinograph/planning/factors/state_target_factor.h"
#include "kinograph/planning/user_terms.h"

#include <stdexcept>

namespace kinograph::planning {
namespace {
std::vector<RowSpec> target_rows(size_t num_keys, int n, const Eigen::VectorXd& target,
                                 double scale) {
  if (n <= 0 || target.size() != static_cast<Eigen::Index>(num_keys) * n) {
    throw std::invalid_argument("StateTargetFactor: target has the wrong size");
  }
  if (!(scale > 0)) throw std::invalid_argument("StateTargetFactor: scale must be positive");
  std::vector<RowSpec> rows(target.size());
  for (Eigen::Index i = 0; i < target.size(); ++i) {
    rows[i].kind = RowKind::kEquality;
    rows[i].lower = target[i];
    rows[i].scale = scale;
  }
  return rows;
}
}  // namespace

StateTargetFactor::StateTargetFactor(std::vector<graph::Key> keys, int n,
                                     const Eigen::VectorXd& target, double scale)
    : StateTargetFactor(keys, n, target_rows(keys.size(), n, target, scale)) {}

StateTargetFactor::StateTargetFactor(std::vector<graph::Key> keys, int n, std::vector<RowSpec> rows)
    : ConstrainedFactor(keys, std::vector<int>(keys.size(), n), std::move(rows)), n_(n) {
  declare_linear();
}

std::shared_ptr<StateTargetFactor> StateTargetFactor::soft(std::vector<graph::Key> keys, int n,
                                                           const Eigen::VectorXd& target,
                                                           double weight) {
  if (!(weight > 0)) throw std::invalid_argument("StateTargetFactor: weight must be positive");
  std::vector<RowSpec> rows = target_rows(keys.size(), n, target, 1.0);
  for (RowSpec& r : rows) {
    r.kind = RowKind::kSoft;
    r.weight = weight;
  }
  return std::shared_ptr<StateTargetFactor>(new StateTargetFactor(std::move(keys), n, rows));
}

void StateTargetFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                                const graph::Jacobians* J) const {
  const int m = static_cast<int>(keys().size());
  for (int i = 0; i < m; ++i) {
    z.segment(i * n_, n_) = x[i];
    if (J != nullptr) J->block(i).middleRows(i * n_, n_).setIdentity();
  }
}

Eigen::VectorXd StateTargetFactor::target() const {
  Eigen::VectorXd t(residual_dim());
  for (int i = 0; i < residual_dim(); ++i) t[i] = rows()[i].lower;
  return t;
}

std::string StateTargetFactor::describe_row(int row, double z, const RowContext& c) const {
  const int j = row % n_;
  const graph::Key key = keys()[static_cast<size_t>(row / n_)];
  const int derivative = key.kind() == 'v' ? 1 : key.kind() == 'a' ? 2 : 0;
  const char* const quantity[] = {"position", "velocity", "acceleration"};
  const std::string u = joint_unit(c.model, j, derivative);
  return joint_label(c.model, j) + " " + quantity[derivative] + " is " + number(z) + " " + u +
         ", " + number(c.violation) + " " + u + " from its " + c.role + " " +
         number(rows()[static_cast<size_t>(row)].lower) + " " + u + " at " +
         at_time(key.step() * c.dt);
}

}  // namespace kinograph::planning
