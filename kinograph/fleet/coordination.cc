#include "kinograph/fleet/coordination.h"

#include <algorithm>
#include <tuple>

namespace kinograph::fleet {

bool outranks(const PriorityKey& a, const PriorityKey& b) {
  return std::tie(a.goal_utime, a.robot) < std::tie(b.goal_utime, b.robot);
}

std::string to_string(Treatment treatment) {
  return treatment == Treatment::kAlongPlan ? "along plan" : "held at state";
}

Decision coordinate(const PriorityKey& own, const std::vector<NeighbourView>& neighbours,
                    const PlannedAround& planned, bool own_goal_changed) {
  Decision d;
  d.treatment.reserve(neighbours.size());
  std::string trigger;
  for (const NeighbourView& n : neighbours) {
    const bool higher = outranks(n.key, own);
    const bool follow = higher && !n.silent && n.plan_id.has_value();
    d.treatment.push_back(follow ? Treatment::kAlongPlan : Treatment::kHeldAtState);
    const std::int64_t entry = follow ? *n.plan_id : kHeldMark;
    d.around[n.name] = entry;
    if (!higher || !trigger.empty()) continue;
    // Only a higher-priority neighbour's change moves this robot; a lower one yields to it.
    const auto was = planned.find(n.name);
    if (was == planned.end() || was->second != entry) {
      trigger = follow ? "neighbour '" + n.name + "' (higher priority) has plan " +
                             std::to_string(entry)
                       : "neighbour '" + n.name + "' (higher priority) is " +
                             (n.silent ? "silent" : "without a plan") + ", held at its state";
    }
  }
  if (own_goal_changed) {
    d.replan = true;
    d.reason = "own goal changed";
  } else if (planned.empty()) {
    d.reason = "no plan yet: waiting for a goal";
  } else if (!trigger.empty()) {
    d.replan = true;
    d.reason = trigger;
  } else {
    d.reason = "no higher-priority neighbour changed";
  }
  return d;
}

WaitPlan wait_for(double blocking_end, double own_start, double horizon) {
  WaitPlan w;
  w.wait = std::max(0.0, blocking_end - own_start);
  w.horizon = horizon + w.wait;
  return w;
}

std::string deadlock_reason(const std::string& neighbour, const std::string& why) {
  return "deadlock: no plan around neighbour '" + neighbour +
         "', not even after waiting for its plan to end: " + why;
}

}  // namespace kinograph::fleet
