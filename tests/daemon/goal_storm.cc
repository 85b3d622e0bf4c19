// goal_storm: a real LCM client that floods a kinographd with goals (and obstacle moves) and
// checks that every goal is answered exactly once, the newest by a valid plan, and that the
// daemon's heartbeat accounts for every goal. Used by the storm and burst tests in
// tests/daemon/*.sh.
//   goal_storm --url URL --prefix RR --goals N [--rate HZ] [--obstacle-rate HZ] [--q 0.8,-0.4]
//              [--first-id 1] [--answer-timeout S] [--json FILE] [--newest plan|cancelled]
//              [--state-rate HZ --state-q q,... --state-joints name,...]
// --rate 0 sends the goals back to back. After the last goal it prints "sent N goals" (the
// burst test's cue to resume a stopped daemon) and waits for the answers. Exit 0 when all is
// well, 1 with the reasons on stderr otherwise. --newest cancelled: the newest goal must be
// answered CANCELLED (the daemon is stopped while it is pending), not by a valid plan.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "kinograph/goal_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace {

using Clock = std::chrono::steady_clock;

// What the daemon sent back, gathered on the receive thread.
class Answers {
 public:
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    kinograph::plan_t p;
    std::lock_guard lock(mutex_);
    if (!kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), p).ok) {
      ++malformed_;
      return;
    }
    // Replans of the current goal (after an obstacle move) answer it again; only the first
    // answer of each goal counts as its answer.
    auto [it, first] = first_answer_.try_emplace(p.goal_id, p);
    if (first) {
      const auto latency = Clock::now() - sent_at_[p.goal_id];
      latencies_ms_.push_back(std::chrono::duration<double, std::milli>(latency).count());
    } else if (it->second.status != kinograph::plan_t::SUCCESS &&
               it->second.status != kinograph::plan_t::NOT_CONVERGED) {
      ++answered_after_refusal_;  // a superseded or refused goal must not be planned later
    }
    last_answer_[p.goal_id] = p;
    cv_.notify_all();
  }
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    kinograph::planner_status_t s;
    if (!kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), s).ok) {
      return;
    }
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    if (status_) {
      // Received gap against the daemon's own stamps: a stall of the daemon widens both, one of
      // this client (or of the network) only the first.
      const double gap = std::chrono::duration<double>(now - status_at_).count();
      const double sent_gap = 1e-6 * static_cast<double>(s.utime - status_->utime);
      if (gap > max_heartbeat_gap_s_) {
        max_heartbeat_gap_s_ = gap;
        max_gap_sent_gap_s_ = sent_gap;
        max_gap_at_s_ = std::chrono::duration<double>(now - start_).count();
        max_gap_end_utime_ = s.utime;
      }
      max_heartbeat_sent_gap_s_ = std::max(max_heartbeat_sent_gap_s_, sent_gap);
    }
    status_ = s;
    status_at_ = now;
    cv_.notify_all();
  }
  // Our own goals, looped back by the multicast group: once all are seen, they are in the
  // daemon's socket too (the kernel delivers a datagram to every member at once).
  void on_own_goal(const lcm::ReceiveBuffer*, const std::string&) {
    std::lock_guard lock(mutex_);
    ++echoed_;
    cv_.notify_all();
  }
  bool wait_echoed(int64_t n, double timeout_s) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                        [&] { return echoed_ >= n; });
  }
  void mark_sent(int64_t id) {
    std::lock_guard lock(mutex_);
    sent_at_[id] = Clock::now();
  }
  // Waits until every goal in [first, last] has an answer and a heartbeat newer than the last
  // answer accounts for all of them, or until the timeout.
  bool wait_all(int64_t first, int64_t last, double timeout_s) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (int64_t id = first; id <= last; ++id) {
        if (!first_answer_.count(id)) return false;
      }
      // The heartbeat counts every goal since the daemon started (earlier storms too): it must
      // account for all it received, not only for as many as this storm sent.
      return status_ && status_->num_goals_answered >= last - first + 1 &&
             status_->num_goals_received + status_->num_goals_dropped ==
                 status_->num_goals_answered &&
             status_->state == 0 /* IDLE */;
    });
  }

  // Waits until a heartbeat's message contains `text`, or until the timeout.
  bool wait_status_text(const std::string& text, double timeout_s) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      return status_ && status_->message.find(text) != std::string::npos;
    });
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::map<int64_t, kinograph::plan_t> first_answer_, last_answer_;
  std::map<int64_t, Clock::time_point> sent_at_;
  std::vector<double> latencies_ms_;
  std::optional<kinograph::planner_status_t> status_;
  Clock::time_point status_at_;
  const Clock::time_point start_ = Clock::now();
  double max_heartbeat_gap_s_ = 0;       // between two heartbeats' arrival here
  double max_heartbeat_sent_gap_s_ = 0;  // between two heartbeats' utime stamps (daemon's clock)
  double max_gap_sent_gap_s_ = 0;        // the stamps' gap of the longest arrival gap
  double max_gap_at_s_ = 0;              // when that gap ended, seconds after this client started
  int64_t max_gap_end_utime_ = 0;        // and the stamp of the heartbeat that ended it
  int malformed_ = 0;
  int64_t echoed_ = 0;
  int answered_after_refusal_ = 0;
};

std::vector<double> parse_list(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) v.push_back(std::stod(item));
  return v;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"goal_storm: floods a kinographd with goals and checks every one is answered"};
  std::string url, prefix = "RR", q_text = "0.8,-0.4", json_path, heartbeat_text;
  int64_t goals = 40, first_id = 1;
  double rate = 0, obstacle_rate = 0, state_rate = 0, answer_timeout = 60;
  std::string state_q_text;
  app.add_option("--url", url, "LCM URL")->required();
  app.add_option("--prefix", prefix, "daemon channel prefix");
  app.add_option("--goals", goals, "number of goals")->check(CLI::PositiveNumber);
  app.add_option("--rate", rate, "goals per second (0: back to back)");
  app.add_option("--obstacle-rate", obstacle_rate, "obstacle moves per second (0: none)");
  app.add_option("--state-rate", state_rate,
                 "measured states per second, at --state-q on the wall clock (0: none)");
  app.add_option("--state-q", state_q_text, "joint positions of the measured states");
  std::string state_names_text;
  app.add_option("--state-joints", state_names_text, "joint names of the measured states");
  app.add_option("--q", q_text, "base joint goal; goal i adds 0.05 (i mod 5) to joint 1");
  app.add_option("--first-id", first_id, "id of the first goal (then consecutive)");
  app.add_option("--answer-timeout", answer_timeout, "s to wait for answers after the last goal");
  app.add_option("--json", json_path, "write the figures as JSON here");
  std::string newest = "plan";
  app.add_option("--newest", newest, "how the newest goal must be answered")
      ->check(CLI::IsMember({"plan", "cancelled"}));
  app.add_option("--heartbeat-text", heartbeat_text,
                 "also wait (30 s at most) for a heartbeat whose message contains this");
  CLI11_PARSE(app, argc, argv);
  const std::vector<double> q0 = parse_list(q_text);

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "goal_storm: LCM could not start on " << url << "\n";
    return 1;
  }
  Answers answers;
  // This client must not lose answers itself: its queues hold the whole storm.
  lcm.subscribe(prefix + "_PLAN", &Answers::on_plan, &answers)->setQueueCapacity(1000000);
  lcm.subscribe(prefix + "_PLANNER_STATUS", &Answers::on_status, &answers)
      ->setQueueCapacity(100000);
  lcm.subscribe(prefix + "_GOAL", &Answers::on_own_goal, &answers)->setQueueCapacity(1000000);
  std::atomic<bool> stop{false};
  std::thread receiver([&] {
    while (!stop) lcm.handleTimeout(20);
  });

  const auto start = Clock::now();
  const auto goal_period =
      rate > 0 ? std::chrono::duration<double>(1.0 / rate) : std::chrono::duration<double>(0);
  const auto obstacle_period = obstacle_rate > 0
                                   ? std::chrono::duration<double>(1.0 / obstacle_rate)
                                   : std::chrono::duration<double>(1e9);
  auto next_obstacle = start;
  int64_t obstacle_moves = 0;
  const auto state_period = state_rate > 0 ? std::chrono::duration<double>(1.0 / state_rate)
                                           : std::chrono::duration<double>(1e9);
  auto next_state = start;
  int64_t states_sent = 0;
  kinograph::robot_state_t state{};
  if (state_rate > 0) {
    state.position = parse_list(state_q_text);
    std::stringstream names(state_names_text);
    for (std::string name; std::getline(names, name, ',');) state.joint_name.push_back(name);
    state.num_joints = static_cast<int32_t>(state.joint_name.size());
    state.velocity.assign(state.joint_name.size(), 0.0);
  }
  for (int64_t i = 0; i < goals; ++i) {
    const auto due = start + std::chrono::duration_cast<Clock::duration>(goal_period * i);
    // States and obstacle moves stream between the goals, each when it is due.
    while (true) {
      const bool state_first =
          state_rate > 0 && (obstacle_rate <= 0 || next_state <= next_obstacle);
      const auto next = state_first ? next_state : next_obstacle;
      if ((state_rate <= 0 && obstacle_rate <= 0) || next > due) break;
      std::this_thread::sleep_until(next);
      if (state_first) {
        state.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
        lcm.publish(prefix + "_STATE", &state);
        ++states_sent;
        next_state += std::chrono::duration_cast<Clock::duration>(state_period);
        continue;
      }
      kinograph::obstacle_list_t list{};
      kinograph::obstacle_t o{};
      o.id = "storm_ball";
      o.action = kinograph::obstacle_t::ADD_OR_MOVE;
      o.shape = kinograph::obstacle_t::SPHERE;
      o.size[0] = 0.05;
      o.position[0] = 1e-3 * static_cast<double>(obstacle_moves % 100);  // out of reach, moving
      o.position[1] = 3.0;
      o.quaternion[0] = 1;
      list.obstacles.push_back(o);
      list.num_obstacles = 1;
      lcm.publish(prefix + "_OBSTACLES", &list);
      ++obstacle_moves;
      next_obstacle += std::chrono::duration_cast<Clock::duration>(obstacle_period);
    }
    std::this_thread::sleep_until(due);
    kinograph::goal_t g{};
    g.goal_id = first_id + i;
    g.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
    g.kind = kinograph::goal_t::KIND_JOINT_CONFIGURATION;
    g.joint_position = q0;
    g.joint_position[0] += 0.05 * static_cast<double>(i % 5);
    g.num_joints = static_cast<int32_t>(g.joint_position.size());
    g.ee_quaternion[0] = 1;
    answers.mark_sent(g.goal_id);
    lcm.publish(prefix + "_GOAL", &g);
  }
  const double send_s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!answers.wait_echoed(goals, 10)) std::cerr << "goal_storm: own goals not all looped back\n";
  std::cout << "sent " << goals << " goals in " << send_s << " s" << std::endl;

  const int64_t last_id = first_id + goals - 1;
  const bool complete = answers.wait_all(first_id, last_id, answer_timeout);
  const bool text_seen = heartbeat_text.empty() || answers.wait_status_text(heartbeat_text, 30);
  stop = true;
  receiver.join();

  std::lock_guard lock(answers.mutex_);
  std::map<int, int64_t> by_status;
  int64_t answered = 0;
  for (int64_t id = first_id; id <= last_id; ++id) {
    auto it = answers.first_answer_.find(id);
    if (it == answers.first_answer_.end()) continue;
    ++answered;
    ++by_status[it->second.status];
  }
  std::vector<std::string> problems;
  if (!complete) problems.push_back("not every goal was answered within the timeout");
  if (answered != goals) {
    problems.push_back(std::to_string(goals - answered) + " of " + std::to_string(goals) +
                       " goals unanswered");
  }
  const auto last = answers.last_answer_.find(last_id);
  const bool last_valid = last != answers.last_answer_.end() &&
                          last->second.status == kinograph::plan_t::SUCCESS && last->second.valid;
  const bool last_cancelled =
      last != answers.last_answer_.end() && last->second.status == kinograph::plan_t::CANCELLED;
  if (newest == "plan" && !last_valid) problems.push_back("the newest goal has no valid plan");
  if (newest == "cancelled" && !last_cancelled) {
    problems.push_back("the newest goal was not answered CANCELLED");
  }
  if (answers.answered_after_refusal_ > 0) {
    problems.push_back(std::to_string(answers.answered_after_refusal_) +
                       " goals planned after they were answered superseded or refused");
  }
  const auto& st = answers.status_;
  if (!text_seen) problems.push_back("no heartbeat said \"" + heartbeat_text + "\"");
  if (!st) {
    problems.push_back("no heartbeat received");
  } else if (st->num_goals_received + st->num_goals_dropped != st->num_goals_answered) {
    problems.push_back("heartbeat: received + dropped != answered");
  }

  std::ostringstream json;
  json << "{\"goals\": " << goals << ", \"goal_rate_hz\": " << rate
       << ", \"obstacle_rate_hz\": " << obstacle_rate << ", \"obstacle_moves\": " << obstacle_moves
       << ", \"states_sent\": " << states_sent << ", \"send_s\": " << send_s
       << ", \"answered\": " << answered
       << ", \"planned\": " << by_status[kinograph::plan_t::SUCCESS]
       << ", \"superseded\": " << by_status[kinograph::plan_t::SUPERSEDED]
       << ", \"cancelled\": " << by_status[kinograph::plan_t::CANCELLED] << ", \"other_status\": "
       << answered - by_status[kinograph::plan_t::SUCCESS] -
              by_status[kinograph::plan_t::SUPERSEDED] - by_status[kinograph::plan_t::CANCELLED]
       << ", \"last_goal_valid\": " << (last_valid ? "true" : "false")
       << ", \"answer_latency_ms_p50\": " << percentile(answers.latencies_ms_, 0.5)
       << ", \"answer_latency_ms_p99\": " << percentile(answers.latencies_ms_, 0.99)
       << ", \"max_heartbeat_gap_s\": " << answers.max_heartbeat_gap_s_
       << ", \"max_heartbeat_gap_stamped_s\": " << answers.max_gap_sent_gap_s_
       << ", \"max_heartbeat_gap_at_s\": " << answers.max_gap_at_s_
       << ", \"max_heartbeat_gap_end_utime\": " << answers.max_gap_end_utime_
       << ", \"max_heartbeat_stamp_gap_s\": " << answers.max_heartbeat_sent_gap_s_;
  if (st) {
    json << ", \"heartbeat\": {\"received\": " << st->num_goals_received
         << ", \"answered\": " << st->num_goals_answered
         << ", \"superseded\": " << st->num_goals_superseded
         << ", \"dropped\": " << st->num_goals_dropped << "}";
  }
  json << "}";
  std::cout << json.str() << std::endl;
  if (st) std::cout << "last heartbeat message: " << st->message << std::endl;
  if (!json_path.empty()) std::ofstream(json_path) << json.str() << "\n";
  for (const auto& p : problems) std::cerr << "goal_storm: " << p << "\n";
  return problems.empty() ? 0 : 1;
}
