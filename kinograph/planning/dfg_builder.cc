#include "kinograph/planning/dfg_builder.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "kinograph/dynamics/data.h"
#include "kinograph/graph/noise_model.h"

namespace kinograph::planning {

std::vector<size_t> DfgStep::all() const {
  std::vector<size_t> out;
  out.reserve(size());
  for (const auto* v : {&twist, &accel, &wrench, &torque})
    out.insert(out.end(), v->begin(), v->end());
  return out;
}

DfgStep add_dfg_factors(graph::FactorGraph& graph, const dynamics::Model& model, int step,
                        const DfgOptions& options) {
  const int n = model.nq();
  const DfgKeys& k = options.keys;
  std::vector<dynamics::Vector6> external(n, dynamics::Vector6::Zero());
  for (const dynamics::ExternalWrench& w : options.external) {
    if (w.body < 0 || w.body >= n) {
      throw std::invalid_argument("DFG: external wrench on body " + std::to_string(w.body) +
                                  " of a model with " + std::to_string(n) + " bodies");
    }
    external[w.body] += w.wrench;
  }
  const graph::NoiseModelPtr noise6 = graph::isotropic(6, options.sigma);
  const graph::NoiseModelPtr noise1 = graph::isotropic(1, options.sigma);
  auto joint = [&](graph::Key key, int j) { return JointScalar{key, n, j}; };
  const graph::Key q = k.q_key(step), qd = k.qd_key(step), qdd = k.qdd_key(step);

  DfgStep out;
  out.step = step;
  for (int i = 0; i < n; ++i) {
    const int p = model.bodies[i].parent;
    // For a body on the base the parent keys are ignored by the factors; pass its own.
    const int pk = p >= 0 ? p : i;
    out.twist.push_back(graph.add(std::make_shared<DfgTwistFactor>(
        model, i, k.twist_key(i, step), k.twist_key(pk, step), joint(q, i), joint(qd, i), noise6)));
    out.accel.push_back(graph.add(std::make_shared<DfgAccelFactor>(
        model, i, k.accel_key(i, step), k.accel_key(pk, step), k.twist_key(i, step), joint(q, i),
        joint(qd, i), joint(qdd, i), noise6)));
    std::vector<DfgChild> children;
    for (int c = i + 1; c < n; ++c) {
      if (model.bodies[c].parent == i) children.push_back({c, k.wrench_key(c, step), joint(q, c)});
    }
    out.wrench.push_back(graph.add(std::make_shared<DfgWrenchFactor>(
        model, i, k.wrench_key(i, step), k.accel_key(i, step), k.twist_key(i, step),
        std::move(children), external[i], noise6)));
    out.torque.push_back(graph.add(std::make_shared<DfgTorqueFactor>(
        model, i, k.torque_scalar(i, step, n), k.wrench_key(i, step), joint(qd, i), noise1)));
  }
  return out;
}

void set_dfg_values(graph::Values& values, const dynamics::Model& model, dynamics::Data& data,
                    int step, const dynamics::VectorRef& q, const dynamics::VectorRef& qd,
                    const dynamics::VectorRef& qdd, const DfgOptions& options) {
  const int n = model.nq();
  const DfgKeys& k = options.keys;
  dynamics::rnea(model, data, q, qd, qdd, options.external);
  auto put = [&values](graph::Key key, const Eigen::Ref<const Eigen::VectorXd>& v) {
    if (values.contains(key)) {
      values.update(key, v);
    } else {
      values.insert(key, v);
    }
  };
  for (int i = 0; i < n; ++i) {
    put(k.twist_key(i, step), data.V[i]);
    put(k.accel_key(i, step), data.Vdot[i]);
    put(k.wrench_key(i, step), data.F[i]);
    if (!k.torque_vector) put(k.torque_key(i, step), data.tau.segment(i, 1));
  }
  if (k.torque_vector) put(k.torque_key(0, step), data.tau);
}

DfgStep add_dfg_dynamics(graph::FactorGraph& graph, graph::Values& values,
                         const dynamics::Model& model, int step, const DfgOptions& options) {
  const DfgKeys& k = options.keys;
  const Eigen::VectorXd q = values.at(k.q_key(step));
  const Eigen::VectorXd qd = values.at(k.qd_key(step));
  const Eigen::VectorXd qdd = values.at(k.qdd_key(step));
  dynamics::Data data(model);
  set_dfg_values(values, model, data, step, q, qd, qdd, options);
  return add_dfg_factors(graph, model, step, options);
}

double dfg_max_residual(const graph::FactorGraph& graph, const graph::Values& values,
                        const std::vector<size_t>& factors) {
  double worst = 0;
  std::vector<const double*> ptrs;
  Eigen::VectorXd e;
  for (size_t index : factors) {
    const graph::FactorPtr& f = graph.at(index);
    if (!f) continue;
    ptrs.clear();
    for (graph::Key key : f->keys()) ptrs.push_back(values.at(key).data());
    e.setZero(f->residual_dim());
    f->evaluate(graph::FactorValues(ptrs.data(), f->dims().data()), e, nullptr);
    worst = std::max(worst, e.cwiseAbs().maxCoeff());
  }
  return worst;
}

Eigen::VectorXd dfg_torques(const graph::Values& values, const dynamics::Model& model, int step,
                            const DfgKeys& keys) {
  const int n = model.nq();
  if (keys.torque_vector) return values.at(keys.torque_key(0, step));
  Eigen::VectorXd tau(n);
  for (int i = 0; i < n; ++i) tau[i] = values.at(keys.torque_key(i, step))[0];
  return tau;
}

}  // namespace kinograph::planning
