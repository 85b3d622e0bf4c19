#pragma once
// What a PlannerNode under test publishes on RR_PLAN and RR_PLANNER_STATUS, recorded from the
// node's LCM thread for the test thread to wait on (bounded waits on events, never sleeps).
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::daemon {

// Records what the node publishes, from the node's LCM thread, for the test thread to wait on.
class Listener {
 public:
  explicit Listener(lcm::LCM& lcm) {
    // A burst of answers must not overflow LCM's default 30-message queue here.
    lcm.subscribe("RR_PLAN", &Listener::on_plan, this)->setQueueCapacity(100000);
    lcm.subscribe("RR_PLANNER_STATUS", &Listener::on_status, this)->setQueueCapacity(100000);
  }
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    plan_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    std::lock_guard lock(mutex_);
    plans_.push_back(std::move(msg));
    cv_.notify_all();
  }
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    planner_status_t msg;
    ASSERT_TRUE(lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok);
    std::lock_guard lock(mutex_);
    statuses_.push_back(std::move(msg));
    cv_.notify_all();
  }
  // Waits (bounded) until `count` plans have arrived; returns a copy of all of them.
  std::vector<plan_t> wait_plans(size_t count, double timeout_s = 60) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                 [&] { return plans_.size() >= count; });
    return plans_;
  }
  // Waits until a heartbeat accounts for `answered` goals; returns the first that does.
  std::optional<planner_status_t> wait_status_answered(int64_t answered, double timeout_s = 30) {
    std::unique_lock lock(mutex_);
    std::optional<planner_status_t> found;
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (const auto& s : statuses_) {
        if (s.num_goals_answered >= answered) {
          found = s;
          return true;
        }
      }
      return false;
    });
    return found;
  }
  // Waits until `count` heartbeats have arrived.
  bool wait_statuses(size_t count, double timeout_s = 30) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                        [&] { return statuses_.size() >= count; });
  }
  // Waits until a heartbeat says the node is making a plan for the goal of `goal_utime`.
  bool wait_status_planning(int64_t goal_utime, double timeout_s = 30) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (const auto& s : statuses_) {
        if (s.state == planner_status_t::PLANNING && s.planning_goal_utime == goal_utime) return true;
      }
      return false;
    });
  }
  // Waits until some status message mentions `text`.
  bool wait_status_containing(const std::string& text, double timeout_s = 10) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (const auto& s : statuses_) {
        if (s.message.find(text) != std::string::npos) return true;
      }
      return false;
    });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<plan_t> plans_;
  std::vector<planner_status_t> statuses_;
};

}  // namespace kinograph::daemon
