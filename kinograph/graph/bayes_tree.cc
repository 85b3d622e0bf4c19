#include "kinograph/graph/bayes_tree.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

namespace kinograph::graph {

void BayesTree::set_layout(const std::vector<int>& dims, const std::vector<int>& offsets) {
  if (dims.size() < dims_.size()) {
    throw std::invalid_argument("BayesTree::set_layout: variables can only be appended");
  }
  dims_ = dims;
  offsets_ = offsets;
  clique_of_.resize(dims.size(), -1);
  pos_.resize(dims.size(), -1);
  local_offset_.resize(dims.size(), -1);
  changed_flag_.resize(dims.size(), 0);
}

void BayesTree::clear() {
  cliques_.clear();
  free_ids_.clear();
  num_cliques_ = 0;
  std::fill(clique_of_.begin(), clique_of_.end(), -1);
}

int BayesTree::new_clique() {
  int id;
  if (!free_ids_.empty()) {
    id = free_ids_.back();
    free_ids_.pop_back();
    cliques_[id] = Clique();
  } else {
    id = static_cast<int>(cliques_.size());
    cliques_.emplace_back();
  }
  cliques_[id].alive = true;
  ++num_cliques_;
  return id;
}

void BayesTree::remove_clique(int id) {
  Clique& c = cliques_[id];
  for (int v : c.frontals) clique_of_[v] = -1;
  c = Clique();
  free_ids_.push_back(id);
  --num_cliques_;
}

std::vector<int> BayesTree::roots() const {
  std::vector<int> out;
  for (int i = 0; i < clique_capacity(); ++i) {
    if (cliques_[i].alive && cliques_[i].parent < 0) out.push_back(i);
  }
  return out;
}

void BayesTree::detach(const std::vector<int>& marked, std::vector<int>* vars,
                       std::vector<int>* factors, std::vector<int>* orphans) {
  vars->clear();
  factors->clear();
  orphans->clear();
  // Walk up from every marked variable's clique; the set is closed under parents.
  std::vector<int> top;
  std::vector<char> in_top(cliques_.size(), 0);
  for (int v : marked) {
    int c = clique_of_[v];
    while (c >= 0 && !in_top[c]) {
      in_top[c] = 1;
      top.push_back(c);
      c = cliques_[c].parent;
    }
  }
  for (int c : top) {
    for (int child : cliques_[c].children) {
      if (!in_top[child]) orphans->push_back(child);
    }
  }
  for (int o : *orphans) cliques_[o].parent = -1;
  for (int c : top) {
    const Clique& cl = cliques_[c];
    vars->insert(vars->end(), cl.frontals.begin(), cl.frontals.end());
    factors->insert(factors->end(), cl.factors.begin(), cl.factors.end());
    remove_clique(c);
  }
}

int BayesTree::holder(const std::vector<int>& vars) const {
  const auto has = [](const std::vector<int>& list, int v) {
    return std::find(list.begin(), list.end(), v) != list.end();
  };
  for (int v : vars) {
    const int id = v < static_cast<int>(clique_of_.size()) ? clique_of_[v] : -1;
    if (id < 0) continue;
    const Clique& c = cliques_[id];
    const bool all = std::all_of(vars.begin(), vars.end(), [&](int u) {
      return has(c.frontals, u) || has(c.separator, u);
    });
    if (all) return id;
  }
  return -1;
}

bool BayesTree::hold(int factor, const std::vector<int>& vars) {
  const int id = holder(vars);
  if (id < 0) return false;
  cliques_[id].factors.push_back(factor);
  return true;
}

void BayesTree::release(int factor, const std::vector<int>& vars) {
  for (int v : vars) {
    const int c = v < static_cast<int>(clique_of_.size()) ? clique_of_[v] : -1;
    if (c < 0) continue;
    std::vector<int>& list = cliques_[c].factors;
    const auto it = std::find(list.begin(), list.end(), factor);
    if (it != list.end()) {
      list.erase(it);
      return;
    }
  }
}

std::vector<int> BayesTree::build(const std::vector<int>& vars, const std::vector<int>& order,
                                  const std::vector<int>& factors,
                                  const std::vector<LinearizedFactor>& linearized,
                                  const std::vector<int>& orphans) {
  const int m = static_cast<int>(vars.size());
  for (int k = 0; k < m; ++k) pos_[vars[order[k]]] = k;

  // Assign every factor and orphan to the first of its variables in the order.
  std::vector<std::vector<int>> factors_at(m), orphans_at(m);
  auto first_pos = [&](const std::vector<int>& vs) {
    int first = m;
    for (int v : vs) {
      if (pos_[v] < 0) throw std::logic_error("BayesTree::build: variable outside the top");
      first = std::min(first, pos_[v]);
    }
    return first;
  };
  for (int f : factors) {
    const auto& vs = linearized[f].vars;
    if (!vs.empty()) factors_at[first_pos(vs)].push_back(f);
  }
  for (int o : orphans) {
    const auto& sep = cliques_[o].separator;
    if (sep.empty()) throw std::logic_error("BayesTree::build: orphan without separator");
    orphans_at[first_pos(sep)].push_back(o);
  }

  // Symbolic elimination: the separator of k is everything k's factors, orphans and eliminated
  // children connect it to, except k itself. parent(k) is the first separator variable.
  std::vector<std::vector<int>> sep(m);  // positions, ascending
  std::vector<std::vector<int>> elim_children(m);
  std::vector<int> parent(m, -1);
  std::vector<int> stamp(m, -1);
  for (int k = 0; k < m; ++k) {
    auto& s = sep[k];
    stamp[k] = k;
    auto add = [&](int p) {
      if (stamp[p] != k) {
        stamp[p] = k;
        s.push_back(p);
      }
    };
    for (int f : factors_at[k]) {
      for (int v : linearized[f].vars) add(pos_[v]);
    }
    for (int o : orphans_at[k]) {
      for (int v : cliques_[o].separator) add(pos_[v]);
    }
    for (int c : elim_children[k]) {
      for (int p : sep[c]) add(p);
    }
    std::sort(s.begin(), s.end());
    if (!s.empty()) {
      parent[k] = s.front();
      elim_children[s.front()].push_back(k);
    }
  }

  // Supernodes: k joins its parent's clique when its separator is exactly the parent's
  // variables, i.e. |sep(k)| = |sep(parent)| + 1 (sep(k) ⊆ {parent} ∪ sep(parent) always).
  std::vector<int> clique_at(m, -1);
  std::vector<int> created;
  for (int k = m - 1; k >= 0; --k) {
    const int p = parent[k];
    if (p >= 0 && sep[k].size() == sep[p].size() + 1) {
      clique_at[k] = clique_at[p];
      cliques_[clique_at[k]].frontals.push_back(vars[order[k]]);
      continue;
    }
    const int id = new_clique();
    Clique& c = cliques_[id];
    c.fresh = true;
    c.frontals.push_back(vars[order[k]]);
    for (int q : sep[k]) c.separator.push_back(vars[order[q]]);
    c.parent = p >= 0 ? clique_at[p] : -1;
    if (c.parent >= 0) cliques_[c.parent].children.push_back(id);
    clique_at[k] = id;
    created.push_back(id);
  }
  for (int id : created) {
    Clique& c = cliques_[id];
    std::reverse(c.frontals.begin(), c.frontals.end());
    c.frontal_dim = c.separator_dim = 0;
    for (int v : c.frontals) {
      c.frontal_dim += dims_[v];
      clique_of_[v] = id;
    }
    for (int v : c.separator) c.separator_dim += dims_[v];
  }
  for (int k = 0; k < m; ++k) {
    Clique& c = cliques_[clique_at[k]];
    c.factors.insert(c.factors.end(), factors_at[k].begin(), factors_at[k].end());
    for (int o : orphans_at[k]) {
      cliques_[o].parent = clique_at[k];
      c.children.push_back(o);
    }
  }
  for (int v : vars) pos_[v] = -1;
  std::reverse(created.begin(), created.end());  // children before parents
  return created;
}

bool BayesTree::factorize(const std::vector<int>& ids,
                          const std::vector<LinearizedFactor>& linearized,
                          const Eigen::VectorXd* damping, int* bad_slot) {
  for (int id : ids) {
    Clique& c = cliques_[id];
    const int nf = c.frontal_dim;
    const int n = nf + c.separator_dim;
    int off = 0;
    for (int v : c.frontals) {
      local_offset_[v] = off;
      off += dims_[v];
    }
    for (int v : c.separator) {
      local_offset_[v] = off;
      off += dims_[v];
    }
    if (work_H_.rows() < n) {
      work_H_.resize(n, n);
      work_g_.resize(n);
    }
    auto H = work_H_.topLeftCorner(n, n);
    auto g = work_g_.head(n);
    H.setZero();
    g.setZero();
    // Gather the clique's own factors and its children's marginals (orphans included).
    for (int f : c.factors) {
      const LinearizedFactor& lf = linearized[f];
      if (lf.zero) continue;
      const int nv = static_cast<int>(lf.vars.size());
      for (int a = 0; a < nv; ++a) {
        const int va = lf.vars[a], la = local_offset_[va], da = dims_[va];
        g.segment(la, da) += lf.g.segment(lf.offsets[a], da);
        for (int b = 0; b < nv; ++b) {
          const int vb = lf.vars[b];
          H.block(la, local_offset_[vb], da, dims_[vb]) +=
              lf.H.block(lf.offsets[a], lf.offsets[b], da, dims_[vb]);
        }
      }
    }
    for (int child : c.children) {
      const Clique& ch = cliques_[child];
      int ra = 0;
      for (int va : ch.separator) {
        const int la = local_offset_[va], da = dims_[va];
        g.segment(la, da) += ch.marginal_g.segment(ra, da);
        int rb = 0;
        for (int vb : ch.separator) {
          H.block(la, local_offset_[vb], da, dims_[vb]) +=
              ch.marginal_H.block(ra, rb, da, dims_[vb]);
          rb += dims_[vb];
        }
        ra += da;
      }
    }
    if (damping != nullptr) {
      for (int v : c.frontals) {
        H.diagonal().segment(local_offset_[v], dims_[v]) += damping->segment(offsets_[v], dims_[v]);
      }
    }
    for (int v : c.frontals) local_offset_[v] = -1;
    for (int v : c.separator) local_offset_[v] = -1;

    // Partial Cholesky: H_FF = L Lᵀ, R_FF = Lᵀ, R_FS = L⁻¹H_FS, d = −L⁻¹g_F; the Schur
    // complement on the separator is the marginal passed up.
    Eigen::Ref<Eigen::MatrixXd> H_FF = H.topLeftCorner(nf, nf);
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(H_FF);
    if (llt.info() != Eigen::Success) {
      if (bad_slot != nullptr) *bad_slot = c.frontals.front();
      return false;
    }
    const auto L = H.topLeftCorner(nf, nf).triangularView<Eigen::Lower>();
    c.R.resize(nf, n);
    c.R.leftCols(nf) = H.topLeftCorner(nf, nf).transpose().triangularView<Eigen::Upper>();
    c.R.rightCols(n - nf) = H.topRightCorner(nf, n - nf);
    L.solveInPlace(c.R.rightCols(n - nf));
    c.d = -g.head(nf);
    L.solveInPlace(c.d);
    const auto RS = c.R.rightCols(n - nf);
    c.marginal_H = H.bottomRightCorner(n - nf, n - nf);
    c.marginal_H.noalias() -= RS.transpose() * RS;
    c.marginal_g = g.tail(n - nf);
    c.marginal_g.noalias() += RS.transpose() * c.d;
  }
  return true;
}

int BayesTree::back_substitute(double wildfire, Eigen::VectorXd& delta, std::vector<int>* changed) {
  std::vector<int> stack = roots();
  std::vector<int> flagged;
  int solved = 0;
  while (!stack.empty()) {
    const int id = stack.back();
    stack.pop_back();
    const Clique& c = cliques_[id];
    bool solve = c.fresh;
    for (size_t i = 0; !solve && i < c.separator.size(); ++i) solve = changed_flag_[c.separator[i]];
    if (!solve) continue;
    ++solved;
    const int nf = c.frontal_dim;
    const int ns = c.separator_dim;
    if (work_x_.size() < nf + ns) work_x_.resize(nf + ns);
    auto xs = work_x_.segment(nf, ns);
    int o = 0;
    for (int v : c.separator) {
      xs.segment(o, dims_[v]) = delta.segment(offsets_[v], dims_[v]);
      o += dims_[v];
    }
    auto xf = work_x_.head(nf);
    xf = c.d;
    xf.noalias() -= c.R.rightCols(ns) * xs;
    c.R.leftCols(nf).triangularView<Eigen::Upper>().solveInPlace(xf);
    o = 0;
    for (int v : c.frontals) {
      auto old = delta.segment(offsets_[v], dims_[v]);
      const double change = (xf.segment(o, dims_[v]) - old).cwiseAbs().maxCoeff();
      if (change > 0) {
        if (changed != nullptr) changed->push_back(v);
        old = xf.segment(o, dims_[v]);
      }
      if (change > wildfire) {
        changed_flag_[v] = 1;
        flagged.push_back(v);
      }
      o += dims_[v];
    }
    stack.insert(stack.end(), c.children.begin(), c.children.end());
  }
  for (int v : flagged) changed_flag_[v] = 0;
  return solved;
}

void BayesTree::clear_fresh() {
  for (auto& c : cliques_) c.fresh = false;
}

void BayesTree::gradient(Eigen::VectorXd& out) const {
  out.setZero();
  for (const Clique& c : cliques_) {
    if (!c.alive) continue;
    const Eigen::VectorXd Rtd = c.R.transpose() * c.d;
    int o = 0;
    for (int v : c.frontals) {
      out.segment(offsets_[v], dims_[v]) += Rtd.segment(o, dims_[v]);
      o += dims_[v];
    }
    for (int v : c.separator) {
      out.segment(offsets_[v], dims_[v]) += Rtd.segment(o, dims_[v]);
      o += dims_[v];
    }
  }
}

namespace {
// Gathers a clique's variables (frontals then separator) from a vector laid out like delta.
Eigen::VectorXd gather(const Clique& c, const Eigen::VectorXd& v, const std::vector<int>& dims,
                       const std::vector<int>& offsets) {
  Eigen::VectorXd x(c.frontal_dim + c.separator_dim);
  int o = 0;
  for (const auto* list : {&c.frontals, &c.separator}) {
    for (int s : *list) {
      x.segment(o, dims[s]) = v.segment(offsets[s], dims[s]);
      o += dims[s];
    }
  }
  return x;
}
}  // namespace

double BayesTree::r_norm_squared(const Eigen::VectorXd& v) const {
  double sum = 0;
  for (const Clique& c : cliques_) {
    if (c.alive) sum += (c.R * gather(c, v, dims_, offsets_)).squaredNorm();
  }
  return sum;
}

double BayesTree::model_cost(const Eigen::VectorXd& delta) const {
  double sum = 0;
  for (const Clique& c : cliques_) {
    if (c.alive) sum += 0.5 * (c.R * gather(c, delta, dims_, offsets_) - c.d).squaredNorm();
  }
  return sum;
}

std::string BayesTree::check_invariants(const std::vector<int>& expected_vars,
                                        const std::vector<int>& expected_factors) const {
  std::vector<int> frontal_count(dims_.size(), 0);
  std::vector<int> factor_count;
  int alive = 0;
  for (int id = 0; id < clique_capacity(); ++id) {
    const Clique& c = cliques_[id];
    if (!c.alive) continue;
    ++alive;
    const std::string name = "clique " + std::to_string(id);
    for (int v : c.frontals) {
      ++frontal_count[v];
      if (clique_of_[v] != id) return name + ": clique_of disagrees for slot " + std::to_string(v);
    }
    for (int f : c.factors) {
      if (f >= static_cast<int>(factor_count.size())) factor_count.resize(f + 1, 0);
      ++factor_count[f];
    }
    if (c.parent < 0) {
      if (!c.separator.empty()) return name + ": root with a non-empty separator";
      continue;
    }
    const Clique& p = cliques_[c.parent];
    if (!p.alive) return name + ": dead parent";
    if (std::count(p.children.begin(), p.children.end(), id) != 1) {
      return name + ": parent does not list it as a child exactly once";
    }
    for (int v : c.separator) {
      const bool in_parent = std::count(p.frontals.begin(), p.frontals.end(), v) +
                                 std::count(p.separator.begin(), p.separator.end(), v) >
                             0;
      if (!in_parent) {
        return name + ": separator slot " + std::to_string(v) + " not in the parent's variables";
      }
    }
    for (int child : c.children) {
      if (!cliques_[child].alive || cliques_[child].parent != id) {
        return name + ": child link broken";
      }
    }
  }
  if (alive != num_cliques_) return "clique count disagrees";
  for (int v : expected_vars) {
    if (frontal_count[v] != 1) {
      return "slot " + std::to_string(v) + " is frontal in " + std::to_string(frontal_count[v]) +
             " cliques";
    }
  }
  int total_frontals = 0;
  for (int n : frontal_count) total_frontals += n;
  if (total_frontals != static_cast<int>(expected_vars.size())) {
    return "the tree holds variables that should not be there";
  }
  std::vector<int> expected_count;
  for (int f : expected_factors) {
    if (f >= static_cast<int>(expected_count.size())) expected_count.resize(f + 1, 0);
    ++expected_count[f];
  }
  expected_count.resize(std::max(expected_count.size(), factor_count.size()), 0);
  factor_count.resize(expected_count.size(), 0);
  for (size_t f = 0; f < expected_count.size(); ++f) {
    if (factor_count[f] != expected_count[f]) {
      return "factor " + std::to_string(f) + " is held by " + std::to_string(factor_count[f]) +
             " cliques, expected " + std::to_string(expected_count[f]);
    }
  }
  return {};
}

}  // namespace kinograph::graph
