// PlannerNodeOptions, each set by a test that fails when the node ignores it: the channel
// prefix, the heartbeat period and the LCM URL. (PlannerNodeOptions::replanning is pinned by
// planner_node_test's ReplanFixture tests: BatchModeWarmStartsObstacleReplans,
// BatchSolvesAreInTheDfgFormulationWhenAsked, AFailedReplanIs*.) In-process, no network.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "daemon/planner_node.h"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/io/scene.h"
#include "lcmtypes/safe_decode.h"
#include "tests/daemon/rr_scene.h"

namespace kinograph::daemon {
namespace {

planning::Scene scene() { return testing::rr_daemon_scene(); }

goal_t joint_goal(int64_t id, std::vector<double> q) {
  goal_t g{};
  g.goal_id = id;
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  g.num_joints = static_cast<int32_t>(q.size());
  g.joint_position = std::move(q);
  g.ee_quaternion[0] = 1;
  return g;
}

// Counts what arrives on a channel prefix's PLAN and PLANNER_STATUS channels.
class Listener {
 public:
  Listener(lcm::LCM& lcm, const std::string& prefix) {
    lcm.subscribe(prefix + "_PLAN", &Listener::on_plan, this);
    lcm.subscribe(prefix + "_PLANNER_STATUS", &Listener::on_status, this);
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
    ++statuses_;
    status_utimes_.push_back(msg.utime);
    cv_.notify_all();
  }
  // Waits (bounded) for `count` plans; returns all that arrived.
  std::vector<plan_t> wait_plans(size_t count, double timeout_s) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                 [&] { return plans_.size() >= count; });
    return plans_;
  }
  // Waits (bounded) for `count` status messages; returns how many arrived.
  int wait_statuses(int count, double timeout_s) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                 [&] { return statuses_ >= count; });
    return statuses_;
  }
  // The shortest time between two consecutive statuses by their own stamps (µs).
  int64_t shortest_status_gap_us() {
    std::lock_guard lock(mutex_);
    int64_t gap = std::numeric_limits<int64_t>::max();
    for (size_t i = 1; i < status_utimes_.size(); ++i) {
      gap = std::min(gap, status_utimes_[i] - status_utimes_[i - 1]);
    }
    return gap;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<plan_t> plans_;
  int statuses_ = 0;
  std::vector<int64_t> status_utimes_;
};

// A node on its own thread over a shared memq:// instance.
class Node {
 public:
  Node(lcm::LCM& lcm, PlannerNodeOptions options)
      : node_(scene(), std::move(options), &lcm), thread_([this] { node_.run(stop_); }) {}
  ~Node() {
    stop_ = true;
    thread_.join();
  }
  PlannerNode& operator*() { return node_; }
  PlannerNode* operator->() { return &node_; }

 private:
  std::atomic<bool> stop_{false};
  PlannerNode node_;
  std::thread thread_;
};

TEST(PlannerNodeOptions, ChannelPrefix) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Listener listener(lcm, "ARM7");
  PlannerNodeOptions options;
  options.channel_prefix = "ARM7";  // the URDF's robot name would give "RR"
  Node node(lcm, options);
  EXPECT_EQ(node->channel("GOAL"), "ARM7_GOAL");
  EXPECT_EQ(node->identity().channel_prefix, "ARM7");
  const goal_t g = joint_goal(5, {0.5, 0.5});
  lcm.publish("ARM7_GOAL", &g);
  const std::vector<plan_t> plans = listener.wait_plans(1, 60);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].goal_id, 5);
  EXPECT_EQ(plans[0].status, plan_t::SUCCESS) << plans[0].status_message;
  EXPECT_GE(listener.wait_statuses(1, 10), 1);
  EXPECT_EQ(node->counters().goals_received, 1);
}

// The heartbeat: with a 10 ms period consecutive planner_status_t are stamped less than the
// default 1 s apart (the node's loop wakes at least every 50 ms, and after a stall it catches up
// with heartbeats back to back, so a busy machine only shortens the gaps). The bound on the
// wait is generous: 20 heartbeats take about a second.
TEST(PlannerNodeOptions, StatusPeriod) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Listener listener(lcm, "RR");
  PlannerNodeOptions options;
  options.status_period_s = 0.01;
  Node node(lcm, options);
  ASSERT_GE(listener.wait_statuses(20, 120), 20);
  EXPECT_LT(listener.shortest_status_gap_us(), 500000);
  EXPECT_EQ(node->counters().plans_published, 0) << "only heartbeats: nothing was asked";
}

// The node opens options.lcm_url when given no LCM instance: here an LCM log file (read mode)
// holding one goal, which the node receives; the default URL (made memq:// here, so nothing
// leaves the process) would receive nothing. An unknown provider throws, naming the URL.
TEST(PlannerNodeOptions, LcmUrl) {
  ::setenv("LCM_DEFAULT_URL", "memq://", 1);
  const std::string log = (std::filesystem::temp_directory_path() /
                           ("kinograph_options_test_" + std::to_string(::getpid()) + ".lcmlog"))
                              .string();
  {
    lcm::LogFile file(log, "w");
    ASSERT_TRUE(file.good());
    goal_t g = joint_goal(9, {0.5, 0.5});
    std::vector<uint8_t> bytes(g.getEncodedSize());
    g.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    lcm::LogEvent e{};
    e.timestamp = 1;
    e.channel = "RR_GOAL";
    e.datalen = static_cast<int32_t>(bytes.size());
    e.data = bytes.data();
    ASSERT_EQ(file.writeEvent(&e), 0);
  }
  {
    PlannerNodeOptions options;
    options.lcm_url = "file://" + log + "?mode=r&speed=0";
    PlannerNode node(scene(), options);
    std::atomic<bool> stop{false};
    std::thread thread([&] { node.run(stop); });
    // The goal is counted on the LCM thread as it is read (bounded wait).
    for (int i = 0; i < 1000 && node.counters().goals_received == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    stop = true;
    thread.join();
    EXPECT_EQ(node.counters().goals_received, 1);
  }
  std::filesystem::remove(log);
  PlannerNodeOptions bad;
  bad.lcm_url = "nonesuch://nowhere";
  try {
    PlannerNode node(scene(), bad);
    ADD_FAILURE() << "an unknown LCM provider must throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nonesuch://nowhere"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kinograph::daemon
