#include "daemon/planner_node.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>
#include <thread>

#include "kinograph/planner_status_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::daemon {
namespace {

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

}  // namespace

PlannerNode::PlannerNode(planning::Scene scene, PlannerNodeOptions options, lcm::LCM* shared)
    : scene_(std::move(scene)), options_(std::move(options)), replanner_(options_.replanning) {
  if (!scene_.problem.model) throw std::invalid_argument("PlannerNode: the scene has no robot");
  identity_.model_name = scene_.problem.model->name;
  identity_.channel_prefix =
      options_.channel_prefix.empty() ? upper(identity_.model_name) : options_.channel_prefix;
  if (shared) {
    lcm_ = shared;
  } else {
    owned_lcm_ = std::make_unique<lcm::LCM>(options_.lcm_url);
    lcm_ = owned_lcm_.get();
  }
  if (!lcm_->good()) {
    throw std::runtime_error(
        "LCM could not start on \"" +
        (options_.lcm_url.empty() ? std::string("default URL") : options_.lcm_url) +
        "\" (for udpm a multicast route is needed, see docs/network.md)");
  }
  next_obstacle_id_ = static_cast<int>(scene_.problem.obstacles.size());
  for (const auto& o : scene_.problem.obstacles) {
    next_obstacle_id_ = std::max(next_obstacle_id_, o.id + 1);
  }
  subscriptions_ = {lcm_->subscribe(channel("GOAL"), &PlannerNode::on_goal, this),
                    lcm_->subscribe(channel("OBSTACLES"), &PlannerNode::on_obstacles, this),
                    lcm_->subscribe(channel("STATE"), &PlannerNode::on_state, this)};
  const int capacities[] = {kGoalQueueCapacity, kObstacleQueueCapacity, kStateQueueCapacity};
  for (std::size_t i = 0; i < subscriptions_.size(); ++i) {
    subscriptions_[i]->setQueueCapacity(capacities[i]);
  }
}

// A shared LCM instance outlives the node: its handlers must not call into a destroyed node.
PlannerNode::~PlannerNode() {
  for (lcm::Subscription* s : subscriptions_) {
    if (s != nullptr) lcm_->unsubscribe(s);
  }
}

std::string PlannerNode::channel(const std::string& suffix) const {
  return identity_.channel_prefix + "_" + suffix;
}

NodeCounters PlannerNode::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

int64_t PlannerNode::now_utime() const {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

void PlannerNode::reject(const std::string& reason) {
  spdlog::warn("rejected: {}", reason);
  {
    std::lock_guard lock(mutex_);
    ++counters_.messages_rejected;
    last_message_ = reason;
  }
  publish_status();
}

void PlannerNode::answer_with_failure(int8_t status, const std::string& reason, int64_t goal_id) {
  int64_t plan_id;
  {
    std::lock_guard lock(mutex_);
    plan_id = next_plan_id_++;
    ++counters_.plans_published;
    ++counters_.failures;
    ++counters_.goals_answered;
    if (status == plan_t::SUPERSEDED) ++counters_.goals_superseded;
  }
  plan_t answer = messages::failure_message(status, reason, identity_.model_name, plan_id, goal_id,
                                            now_utime());
  lcm_->publish(channel("PLAN"), &answer);
}

void PlannerNode::answer_superseded(const Intake& taken) {
  // Superseded goals were always replaced by a newer valid goal, which `taken` holds.
  const std::string newest = taken.goal ? std::to_string(taken.goal->goal_id) : "?";
  for (const int64_t id : taken.superseded) {
    answer_with_failure(plan_t::SUPERSEDED,
                        "superseded by goal " + newest + " before planning began", id);
  }
  for (const LostGoals& gap : taken.lost) {
    spdlog::warn("goals {}..{} never arrived (lost in transport); answered SUPERSEDED", gap.first,
                 gap.last);
    for (int64_t id = gap.first; id <= gap.last; ++id) {
      answer_with_failure(plan_t::SUPERSEDED,
                          "goal " + std::to_string(id) +
                              " did not reach the planner (lost in transport); goal " +
                              std::to_string(gap.revealed_by) + " is newer",
                          id);
    }
  }
}

void PlannerNode::on_goal(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  goal_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed goal_t: " + s.reason);
    return;
  }
  if (msg.goal_id >= 0) {
    std::optional<LostGoals> lost;
    if (options_.answer_goal_id_gaps) lost = goal_ids_.next(msg.goal_id);
    std::lock_guard lock(mutex_);
    ++counters_.goals_received;
    last_goal_id_ = msg.goal_id;
    if (lost) {
      counters_.goals_dropped += lost->count();
      intake_.lost.push_back(*lost);
    }
  }
  GoalRequest request;
  if (Check c = messages::goal_from_message(msg, *scene_.problem.model, identity_, request);
      !c.ok) {
    reject(channel + ": " + c.reason);
    // The sender named a goal: answer it, so no goal ever goes unanswered.
    if (msg.goal_id >= 0) answer_with_failure(plan_t::INVALID_GOAL, c.reason, msg.goal_id);
    return;
  }
  Intake arrived;
  arrived.goal = std::move(request);
  intake_.absorb(std::move(arrived));
}

void PlannerNode::on_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  obstacle_list_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed obstacle_list_t: " + s.reason);
    return;
  }
  Intake arrived;
  if (Check c = messages::obstacles_from_message(msg, arrived.obstacles); !c.ok) {
    reject(channel + ": " + c.reason);
    return;
  }
  arrived.replace_all = msg.replace_all;
  intake_.absorb(std::move(arrived));
}

void PlannerNode::on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  robot_state_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed robot_state_t: " + s.reason);
    return;
  }
  Intake arrived;
  arrived.state.emplace();
  if (Check c = messages::state_from_message(msg, *scene_.problem.model, identity_, *arrived.state);
      !c.ok) {
    reject(channel + ": " + c.reason);
    return;
  }
  arrived.states = 1;
  intake_.absorb(std::move(arrived));
}

void PlannerNode::hand_over() {
  if (intake_.empty()) return;
  {
    std::lock_guard lock(mutex_);
    if (intake_.state) latest_state_ = std::move(intake_.state);
    state_count_ += intake_.states;
    intake_.state.reset();
    intake_.states = 0;
    pending_.absorb(std::move(intake_));
  }
  intake_ = Intake{};
  wake_.notify_one();
}

bool PlannerNode::apply_obstacles(const std::vector<ObstacleUpdate>& updates, bool replace_all) {
  bool changed = false;
  if (replace_all) {
    // The list is the whole world: obstacles it does not name go; the ones it names keep their
    // ids, so that the planner sees a move rather than a removal and an addition.
    for (auto it = live_obstacles_.begin(); it != live_obstacles_.end();) {
      const bool named = std::any_of(updates.begin(), updates.end(), [&](const ObstacleUpdate& u) {
        return !u.remove && u.id == it->first;
      });
      if (named) {
        ++it;
      } else {
        it = live_obstacles_.erase(it);
        changed = true;
      }
    }
  }
  // The world's bound (scene obstacles included) is checked before anything is added.
  const std::size_t fixed = scene_.problem.obstacles.size();
  std::vector<std::string> refused;
  for (const auto& u : updates) {
    auto it = live_obstacles_.find(u.id);
    if (!u.remove && it == live_obstacles_.end() &&
        fixed + live_obstacles_.size() >= static_cast<std::size_t>(collision::kMaxObstacles)) {
      refused.push_back(u.id);
      continue;
    }
    if (u.remove) {
      if (it != live_obstacles_.end()) {
        live_obstacles_.erase(it);
        changed = true;
      } else {
        spdlog::info("obstacle \"{}\" to remove is not known; ignored", u.id);
      }
      continue;
    }
    collision::Obstacle o;
    o.id = it != live_obstacles_.end() ? it->second.id : next_obstacle_id_++;
    o.shape = u.shape;
    o.pose = u.pose;
    live_obstacles_[u.id] = std::move(o);
    changed = true;
  }
  if (!refused.empty()) {
    reject("obstacle \"" + refused.front() + "\"" +
           (refused.size() > 1 ? " and " + std::to_string(refused.size() - 1) + " more" : "") +
           " not added: the world holds the most obstacles it may, " +
           std::to_string(collision::kMaxObstacles) + " (scene and LCM together)");
  }
  return changed;
}

void PlannerNode::plan_and_publish(const GoalRequest& goal, bool replan) {
  planning::Problem problem = scene_.problem;
  bool new_state = false;
  {
    std::lock_guard lock(mutex_);
    state_ = planner_status_t::PLANNING;
    // A measured state, when there is one, is where the robot is: plan from it.
    if (latest_state_) {
      problem.start_q = latest_state_->q;
      problem.start_qd = latest_state_->qd;
    }
    new_state = state_count_ != used_state_count_;
    used_state_count_ = state_count_;
  }
  for (const auto& [name, obstacle] : live_obstacles_) problem.obstacles.push_back(obstacle);
  problem.goal = goal.goal;
  if (goal.duration_s > 0) problem.horizon = goal.duration_s;

  planning::Plan plan;
  bool threw = false;
  std::string error;
  try {
    plan = replanner_.plan(problem, /*new_goal=*/!replan);
  } catch (const std::exception& e) {
    threw = true;
    error = e.what();
  }
  const planning::ReplanReport& report = replanner_.last_report();
  // A state the incremental planner refused (or never saw, after an exception) is offered again.
  if (threw || !plan.success()) {
    std::lock_guard lock(mutex_);
    if (new_state) --used_state_count_;
  }

  int64_t plan_id;
  {
    std::lock_guard lock(mutex_);
    plan_id = next_plan_id_++;
    last_plan_id_ = plan_id;
    ++counters_.plans_published;
    if (!replan) ++counters_.goals_answered;
    if (replan) ++counters_.replans;
    if (!threw && report.incremental) ++counters_.incremental;
    if (!threw && report.fell_back) ++counters_.fallbacks;
    if (threw || !plan.success()) ++counters_.failures;
    state_ = threw ? planner_status_t::ERROR : planner_status_t::IDLE;
    last_message_ = threw ? error : (plan.success() ? "" : plan.stats.reason);
  }
  plan_t msg;
  if (threw) {
    spdlog::error("goal {}: planner error: {}", goal.goal_id, error);
    msg = messages::failure_message(plan_t::FAILED, "planner error: " + error, identity_.model_name,
                                    plan_id, goal.goal_id, now_utime());
  } else {
    msg = messages::plan_to_message(plan, *problem.model, identity_.model_name, plan_id,
                                    goal.goal_id, now_utime());
    msg.method = report.method;
    spdlog::info("goal {}: plan {} {} ({}, {} iterations, {:.1f} ms)", goal.goal_id, plan_id,
                 plan.success() ? "valid" : "INVALID", msg.method, plan.stats.iterations,
                 plan.stats.solve_time_s * 1e3);
  }
  lcm_->publish(channel("PLAN"), &msg);
  publish_status();
}

void PlannerNode::worker_loop(const std::atomic<bool>& stop) {
  while (true) {
    Intake taken;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(50),
                     [&] { return stop.load() || !pending_.empty(); });
      if (stop.load()) return;
      std::swap(taken, pending_);
    }
    answer_superseded(taken);
    const bool obstacles_changed = (!taken.obstacles.empty() || taken.replace_all) &&
                                   apply_obstacles(taken.obstacles, taken.replace_all);
    if (taken.goal) {
      current_goal_ = taken.goal;
      plan_and_publish(*taken.goal, /*replan=*/false);
    } else if (obstacles_changed && current_goal_) {
      plan_and_publish(*current_goal_, /*replan=*/true);
    }
  }
}

void PlannerNode::publish_status() {
  planner_status_t msg;
  {
    std::lock_guard lock(mutex_);
    msg.utime = now_utime();
    msg.robot = identity_.model_name;
    msg.state = state_;
    msg.last_goal_id = last_goal_id_;
    msg.last_plan_id = last_plan_id_;
    msg.message = last_message_;
    msg.num_plans = counters_.plans_published;
    msg.num_failures = counters_.failures;
    msg.num_goals_received = counters_.goals_received;
    msg.num_goals_answered = counters_.goals_answered;
    msg.num_goals_superseded = counters_.goals_superseded;
    msg.num_goals_dropped = counters_.goals_dropped;
  }
  lcm_->publish(channel("PLANNER_STATUS"), &msg);
}

void PlannerNode::run(const std::atomic<bool>& stop) {
  spdlog::info("kinographd: robot {} on channels {}_*", identity_.model_name,
               identity_.channel_prefix);
  // The worker stops on `done`, not on `stop`, so that an LCM failure also ends it.
  std::atomic<bool> done{false};
  std::thread worker([&] { worker_loop(done); });
  auto next_status = std::chrono::steady_clock::now();
  int handle_failures = 0;
  while (!stop.load()) {
    if (std::chrono::steady_clock::now() >= next_status) {
      publish_status();
      next_status += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(options_.status_period_s));
    }
    // LCM 1.3's udpm handle() occasionally reports a failure for a single datagram (seen when
    // a packet of our own arrives while no handler wants it); only a persistent failure means
    // the transport is gone.
    const int handled = lcm_->handleTimeout(50);
    if (handled < 0) {
      if (++handle_failures > 100) {
        spdlog::error("LCM handle failed 100 times in a row; stopping");
        break;
      }
      spdlog::debug("LCM handle failed once; continuing");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } else {
      handle_failures = 0;
      // A burst (messages less than 1 ms apart, as after a stall) is taken whole before the
      // worker sees any of it, so that only its newest goal is planned; at most 5 ms, so that a
      // steady storm still reaches the worker.
      const auto drain_end = std::chrono::steady_clock::now() + std::chrono::milliseconds(5);
      while (handled > 0 && std::chrono::steady_clock::now() < drain_end &&
             lcm_->handleTimeout(1) > 0) {
      }
    }
    hand_over();
  }
  done = true;
  wake_.notify_all();
  worker.join();
}

}  // namespace kinograph::daemon
