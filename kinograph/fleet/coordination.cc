#include "kinograph/fleet/coordination.h"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <tuple>

namespace kinograph::fleet {

bool outranks(const PriorityKey& a, const PriorityKey& b) {
  return std::tie(a.goal_utime, a.robot) < std::tie(b.goal_utime, b.robot);
}

std::string to_string(Treatment treatment) {
  return treatment == Treatment::kAlongPlan ? "along plan" : "held at state";
}

Decision coordinate(const PriorityKey& own, const std::vector<NeighbourView>& neighbours,
                    const PlannedAround& planned, bool own_goal_changed,
                    const BlockedGoal* blocked) {
  Decision d;
  d.treatment.reserve(neighbours.size());
  std::string trigger;
  for (const NeighbourView& n : neighbours) {
    const bool higher = outranks(n.key, own);
    // Every plan in force is planned around, whatever its robot's priority: a plan made now must
    // keep clear of the motions under way until their robots react to it.
    const bool follow = !n.silent && n.plan_id.has_value();
    d.treatment.push_back(follow ? Treatment::kAlongPlan : Treatment::kHeldAtState);
    const std::int64_t entry = follow ? *n.plan_id : kHeldMark;
    d.around[n.name] = entry;
    d.plans.push_back(n.plan_id);
    if (!higher || !trigger.empty()) continue;
    // Only a higher-priority neighbour's change moves this robot; a lower one yields to it.
    const auto was = planned.find(n.name);
    if (was == planned.end() || was->second != entry) {
      trigger =
          follow ? "neighbour '" + n.name + "' (higher priority) has plan " + std::to_string(entry)
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
  if (own_goal_changed || !blocked || blocked->retries >= kMaxBlockedRetries) return d;
  // The blocker moved: plan again with it moving along its new plan, once per plan of it.
  for (std::size_t i = 0; i < neighbours.size(); ++i) {
    const NeighbourView& n = neighbours[i];
    if (n.name != blocked->neighbour || n.silent || !n.plan_id || n.plan_id == blocked->plan_id) {
      continue;
    }
    // A replan that follows it already is no retry.
    if (d.replan && d.treatment[i] == Treatment::kAlongPlan) break;
    d.treatment[i] = Treatment::kAlongPlan;
    d.around[n.name] = *n.plan_id;
    d.retry = true;
    const std::string retry = "neighbour '" + n.name + "', which blocked the goal, has plan " +
                              std::to_string(*n.plan_id) + ": trying again along it (retry " +
                              std::to_string(blocked->retries + 1) + " of " +
                              std::to_string(kMaxBlockedRetries) + ")";
    d.reason = d.replan ? d.reason + "; " + retry : retry;
    d.replan = true;
    break;
  }
  return d;
}

WaitPlan wait_for(double blocking_end, double own_start, double horizon) {
  WaitPlan w;
  w.wait = std::max(0.0, blocking_end - own_start);
  w.horizon = horizon + w.wait;
  return w;
}

Remedy remedy(const std::string& own, const Blocker& blocker, double own_start, double horizon,
              const std::string& no_wait, const std::string& why) {
  Remedy r;
  const bool moves = blocker.treatment == Treatment::kAlongPlan || blocker.moving;
  // A plan ending within a microsecond (the clock's resolution) has ended.
  if (moves && no_wait.empty() && blocker.plan_end > own_start + 1e-6) {
    r.kind = Remedy::Kind::kWait;
    r.wait = wait_for(blocker.plan_end, 0.0, horizon);
    r.reason = wait_note(blocker.name, r.wait.wait);
    return r;
  }
  if (blocker.treatment == Treatment::kAlongPlan) {
    r.reason = blocked_reason(blocker.name, blocker.prefix, blocker.treatment, own_start, why);
    if (!no_wait.empty() && own_start <= 0) r.reason += " (not waiting: " + no_wait + ")";
    return r;
  }
  if (blocker.blocked_by_own) {
    r.kind = Remedy::Kind::kDeadlock;
    r.reason = deadlock_reason(own, blocker.name, blocker.prefix, why, blocker.cycle);
    return r;
  }
  r.reason = blocked_reason(blocker.name, blocker.prefix, blocker.treatment,
                            blocker.moving ? own_start : 0.0, why);
  return r;
}

namespace {
// Seconds with millisecond digits: "3.000".
std::string seconds(double s) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(3) << s;
  return os.str();
}
}  // namespace

std::string wait_note(const std::string& neighbour, double wait) {
  return "starts " + seconds(wait) + " s late: waits for neighbour '" + neighbour +
         "''s plan to end";
}

namespace {
// What blocker_prefix reads: the neighbour's name, then its prefix in brackets.
std::string tagged(const std::string& name, const std::string& prefix) {
  return "neighbour '" + name + "' [" + prefix + "]";
}
}  // namespace

std::string blocked_reason(const std::string& name, const std::string& prefix, Treatment treatment,
                           double waited, const std::string& why) {
  std::string s = "blocked by " + tagged(name, prefix);
  if (treatment == Treatment::kAlongPlan) {
    s += waited > 0 ? ", even after waiting " + seconds(waited) + " s for its plan to end"
                    : ", moving along its plan";
  } else {
    s += waited > 0 ? ", held where its plan ends, even after waiting " + seconds(waited) +
                          " s for it to get there"
                    : ", held at its state";
  }
  return s + ": " + why;
}

std::string deadlock_reason(const std::string& own, const std::string& name,
                            const std::string& prefix, const std::string& why,
                            const std::vector<std::string>& cycle) {
  if (cycle.size() <= 1) {
    return "deadlock with " + tagged(name, prefix) + ": robots '" + own + "' and '" + prefix +
           "' each stand where the other must go, and neither can move first: " + why;
  }
  std::string robots = "'" + own + "'";
  for (const std::string& r : cycle) robots += " -> '" + r + "'";
  return "deadlock with " + tagged(name, prefix) + ": robots " + robots + " -> '" + own +
         "' each stand where the next must go, and none can move first: " + why;
}

std::string blocker_prefix(const std::string& reason) {
  for (const char* lead : {"blocked by neighbour '", "deadlock with neighbour '"}) {
    const std::size_t at = reason.find(lead);
    if (at == std::string::npos) continue;
    const std::size_t open = reason.find("' [", at + std::string(lead).size());
    const std::size_t close = open == std::string::npos ? open : reason.find(']', open);
    if (close != std::string::npos) return reason.substr(open + 3, close - open - 3);
  }
  return "";
}

}  // namespace kinograph::fleet
