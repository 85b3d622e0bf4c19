#include "kinograph/graph/cancellation.h"

namespace kinograph::graph {

namespace {
thread_local const std::atomic<bool>* t_flag = nullptr;
}  // namespace

CancellationScope::CancellationScope(const std::atomic<bool>& flag) : previous_(t_flag) {
  t_flag = &flag;
}

CancellationScope::~CancellationScope() { t_flag = previous_; }

void throw_if_cancelled() {
  if (t_flag != nullptr && t_flag->load(std::memory_order_relaxed)) throw Cancelled{};
}

const std::atomic<bool>* cancellation_flag() { return t_flag; }

}  // namespace kinograph::graph
