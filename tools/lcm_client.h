#pragma once
// What the CLI's LCM verbs share: a connection, and waiting for the plan that answers a goal.
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>

#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"

namespace kinograph::tools {

/// Collects plan_t messages on one channel and waits for the one answering a goal.
class PlanWaiter {
 public:
  /// Subscribes at once, so that a plan published right after the caller's message is caught.
  PlanWaiter(lcm::LCM& lcm, const std::string& plan_channel);
  /// The first plan_t for `goal_id` received since construction, or nullopt after `timeout_s`.
  std::optional<plan_t> wait(int64_t goal_id, double timeout_s);

 private:
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  lcm::LCM& lcm_;
  int64_t goal_id_ = -1;
  std::optional<plan_t> received_;
};

/// Opens LCM on `url` (empty = default); throws CommandFailure if it cannot.
lcm::LCM& open_lcm(const std::string& url);

/// One line per plan: status, method, time, iterations, validation figures, and its clock.
std::string summarize(const plan_t& plan);
/// The same for a plan of version 1 (old logs), which has no clock.
std::string summarize(const plan_v1_t& plan);

}  // namespace kinograph::tools
