#include "kinograph/graph/factor_graph.h"

#include <atomic>
#include <stdexcept>
#include <string>

namespace kinograph::graph {

namespace {
std::atomic<uint64_t> g_next_structure{1};
}

size_t FactorGraph::add(FactorPtr factor) {
  if (!factor) throw std::invalid_argument("FactorGraph::add: null factor");
  factors_.push_back(std::move(factor));
  ++count_;
  structure_id_ = g_next_structure.fetch_add(1);
  return factors_.size() - 1;
}

void FactorGraph::remove(size_t i) {
  if (i >= factors_.size()) {
    throw std::out_of_range("FactorGraph::remove: no slot " + std::to_string(i));
  }
  if (factors_[i]) {
    factors_[i].reset();
    --count_;
    structure_id_ = g_next_structure.fetch_add(1);
  }
}

double FactorGraph::error(const Values& values) const {
  double e = 0;
  for (const auto& f : factors_) {
    if (f) e += f->error(values);
  }
  return e;
}

}  // namespace kinograph::graph
