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

// plan_t.method names: "batch", "warm-start", "incremental", "batch after warm-start" or
// "batch after incremental".
std::string method_name(std::string stats_method) {
  for (auto [from, to] : {std::pair{"batch-L", "batch"}, std::pair{"batch-W", "warm-start"}}) {
    if (stats_method.rfind(from, 0) == 0) stats_method.replace(0, std::strlen(from), to);
  }
  return stats_method;
}

planning::IncrementalPlannerOptions incremental_options(const PlannerNodeOptions& options) {
  planning::IncrementalPlannerOptions o = options.incremental_planner;
  o.batch = options.planner;
  return o;
}

bool same_obstacle(const collision::Obstacle& a, const collision::Obstacle& b) {
  return a.id == b.id && a.shape.kind == b.shape.kind && a.shape.size == b.shape.size &&
         a.shape.mesh_path == b.shape.mesh_path && a.shape.mesh_scale == b.shape.mesh_scale &&
         a.pose.matrix() == b.pose.matrix() && a.trajectory.empty() && b.trajectory.empty();
}

// Largest joint change between two joint goals; infinity when either is not a joint goal.
double joint_goal_change(const planning::Goal& a, const planning::Goal& b) {
  using Kind = planning::Goal::Kind;
  if (a.kind != Kind::kJoint || b.kind != Kind::kJoint || a.q.size() != b.q.size() ||
      a.q.size() == 0) {
    return std::numeric_limits<double>::infinity();
  }
  return (a.q - b.q).cwiseAbs().maxCoeff();
}

}  // namespace

PlannerNode::PlannerNode(planning::Scene scene, PlannerNodeOptions options, lcm::LCM* shared)
    : scene_(std::move(scene)),
      options_(std::move(options)),
      planner_(options_.planner),
      incremental_(incremental_options(options_)) {
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
  }
  plan_t answer = messages::failure_message(status, reason, identity_.model_name, plan_id, goal_id,
                                            now_utime());
  lcm_->publish(channel("PLAN"), &answer);
}

void PlannerNode::on_goal(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  goal_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed goal_t: " + s.reason);
    return;
  }
  GoalRequest request;
  if (Check c = messages::goal_from_message(msg, *scene_.problem.model, identity_, request);
      !c.ok) {
    reject(channel + ": " + c.reason);
    // The sender named a goal: answer it, so no goal ever goes unanswered.
    if (msg.goal_id >= 0) answer_with_failure(plan_t::INVALID_GOAL, c.reason, msg.goal_id);
    return;
  }
  std::optional<GoalRequest> superseded;
  {
    std::lock_guard lock(mutex_);
    ++counters_.goals_received;
    last_goal_id_ = request.goal_id;
    if (pending_goal_) {
      superseded = std::move(pending_goal_);
      ++counters_.goals_cancelled;
    }
    pending_goal_ = std::move(request);
  }
  wake_.notify_one();
  if (superseded) {
    answer_with_failure(plan_t::CANCELLED, "superseded by a newer goal before planning began",
                        superseded->goal_id);
  }
}

void PlannerNode::on_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  obstacle_list_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed obstacle_list_t: " + s.reason);
    return;
  }
  std::vector<ObstacleUpdate> updates;
  if (Check c = messages::obstacles_from_message(msg, updates); !c.ok) {
    reject(channel + ": " + c.reason);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    if (msg.replace_all) {
      pending_obstacles_.clear();
      pending_replace_all_ = true;
    }
    pending_obstacles_.insert(pending_obstacles_.end(), updates.begin(), updates.end());
  }
  wake_.notify_one();
}

void PlannerNode::on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  robot_state_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel + ": malformed robot_state_t: " + s.reason);
    return;
  }
  MeasuredState state;
  if (Check c = messages::state_from_message(msg, *scene_.problem.model, identity_, state); !c.ok) {
    reject(channel + ": " + c.reason);
    return;
  }
  std::lock_guard lock(mutex_);
  latest_state_ = std::move(state);
  ++state_count_;
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
  for (const auto& u : updates) {
    auto it = live_obstacles_.find(u.id);
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
  return changed;
}

planning::Plan PlannerNode::solve_batch(const planning::Problem& problem, bool replan,
                                        std::string& method) {
  // An obstacle change keeps the goal: the previous plan is the natural starting point.
  const bool warm = replan && last_plan_ && last_plan_->q.rows() == problem.steps + 1;
  planning::Plan plan = planner_.plan(problem, warm ? &*last_plan_ : nullptr);
  // A warm start can be trapped on the wrong side of a new obstacle; a plan from the
  // straight line is the fallback, and its statistics say so.
  if (warm && !plan.success()) {
    spdlog::info("warm-started replan did not validate ({}); planning from scratch",
                 plan.stats.reason);
    const double warm_time = plan.stats.solve_time_s;
    plan = planner_.plan(problem);
    plan.stats.solve_time_s += warm_time;
    plan.stats.method += " after warm-start";
  }
  method = method_name(plan.stats.method);
  return plan;
}

planning::Plan PlannerNode::plan_from_scratch(const planning::Problem& problem,
                                              std::string& method) {
  planning::Plan plan = incremental_.plan(problem);
  incremental_ready_ = plan.success();
  if (!plan.success() && plan.stats.status != "invalid_problem") {
    // iDFGP's first plan carries the batch planner's solution into its tree and settles it
    // (re-solving on its own graph only when neither validates); when that still does not
    // validate, a batch plan from scratch may (seen once in 18 medium goal changes of
    // bench/daemon, with the earlier re-solving first plan). Answer with it; the next change then
    // plans from scratch again.
    planning::Plan batch = planner_.plan(problem);
    if (batch.success()) {
      spdlog::info("iDFGP's first plan did not validate ({}); answering with the batch plan",
                   plan.stats.reason);
      batch.stats.solve_time_s += plan.stats.solve_time_s;
      plan = std::move(batch);
    }
  }
  method = method_name(plan.stats.method);
  return plan;
}

planning::Plan PlannerNode::solve_incremental(const planning::Problem& problem, bool new_goal,
                                              bool new_state, std::string& method) {
  bool from_scratch = !incremental_ready_ || !incremental_.has_plan() ||
                      incremental_.problem().steps != problem.steps;
  // Far goals. Measured with bench/daemon on the iiwa desk (20 problems, 18 with a valid first
  // plan): independent far goals (largest joint change 1.9–5.1 rad) replanned incrementally
  // validated 18/18 (13 directly, 4 after the planner's warm batch fallback, 1 from scratch after
  // an earlier failure), median 97 ms end to end; the batch path (BatchPlanner from the straight
  // line) 18/18, median 98 ms. A fallback costs about 0.5 s, but planning far goals from scratch
  // here cost IncrementalPlanner::plan's median 236 ms every time when its first plan re-solved
  // the batch plan on the incremental graph. Goals within 1.3 rad replanned at 23–47 ms median
  // against 134–156 ms for the batch path. So every goal replans incrementally by default
  // (max_incremental_goal_change = ∞); the option remains for robots where far goals fall back
  // more often. The first plan now carries the batch solution instead (about the batch plan's
  // time plus 10–25 ms); re-measured with it (bench/daemon --max-goal-change 1.5 against the
  // default, 20 problems each): far goals planned from scratch on this node took a median of
  // 63 ms (max 422 ms) against 55 ms (max 253 ms, 4 of 18 fallbacks) replanned incrementally, so
  // the default stays.
  if (!from_scratch && new_goal) {
    const double change = joint_goal_change(incremental_.problem().goal, problem.goal);
    // Pose goals have no joint distance (infinity here): they always replan incrementally.
    if (std::isfinite(change) && change > options_.max_incremental_goal_change) {
      spdlog::info("goal moved by {:.2f} rad (> {:.2f}): planning from scratch", change,
                   options_.max_incremental_goal_change);
      from_scratch = true;
    }
  }
  if (from_scratch) return plan_from_scratch(problem, method);

  // The change from the planner's problem to `problem`: obstacles by stable int id (fixed
  // scene obstacles never change), the goal, the measured start, the duration.
  planning::ProblemChange change;
  const planning::Problem& current = incremental_.problem();
  std::map<int, const collision::Obstacle*> planned;
  for (const auto& o : current.obstacles) planned[o.id] = &o;
  for (const auto& o : scene_.problem.obstacles) planned.erase(o.id);
  for (const auto& o : problem.obstacles) {
    const auto it = planned.find(o.id);
    const bool fixed = std::any_of(scene_.problem.obstacles.begin(), scene_.problem.obstacles.end(),
                                   [&](const collision::Obstacle& f) { return f.id == o.id; });
    if (fixed) continue;
    if (it == planned.end() || !same_obstacle(*it->second, o)) change.add_or_move.push_back(o);
    if (it != planned.end()) planned.erase(it);
  }
  for (const auto& [id, o] : planned) change.remove.push_back(id);
  if (new_goal) change.goal = problem.goal;
  if (new_state) {
    change.start_q = problem.start_q;
    change.start_qd = problem.start_qd;
  }
  if (problem.horizon != current.horizon) change.horizon = problem.horizon;

  planning::Plan plan = incremental_.replan(change);
  // replan() reports a fallback by its batch method (last_stats() is not reset when a change is
  // refused before it is applied, so the plan's own method is the reliable sign).
  const bool fell_back = plan.stats.method != "incremental";
  const planning::IncrementalStats& st = incremental_.last_stats();
  method = fell_back ? "batch after incremental" : "incremental";
  const bool refused = !fell_back && plan.stats.status == "invalid_problem";
  // A refused change left the planner as it was: it can still replan. Any other failure leaves
  // it at a trajectory that did not validate, a poor start for the next change: plan the next
  // goal or obstacle change from scratch.
  incremental_ready_ = plan.success() || (refused && incremental_ready_);
  {
    std::lock_guard lock(mutex_);
    if (!refused) ++counters_.incremental;
    if (fell_back) ++counters_.fallbacks;
  }
  if (!refused) {
    spdlog::info(
        "iDFGP: {} ISAM2 updates, {} multiplier rounds, {} cliques re-eliminated, factors {} "
        "replaced + {} added, {:.1f} ms incremental{}",
        st.updates, st.rounds, st.cliques_reeliminated, st.factors_replaced, st.factors_added,
        st.incremental_time_s * 1e3,
        fell_back ? fmt::format(", fell back ({}) {:.1f} ms", st.fallback_reason,
                                st.fallback_time_s * 1e3)
                  : "");
  }
  // The planner's own fallback is warm-started from the previous plan, which a far goal or an
  // obstacle across the path can leave on the wrong side; a solve from scratch (straight line
  // and detours) is the last resort before answering with a failure.
  if (!plan.success() && !refused && options_.retry_from_scratch) {
    spdlog::info("replan did not validate ({}); planning from scratch", plan.stats.reason);
    const double spent = plan.stats.solve_time_s;
    std::string unused;
    planning::Plan fresh = plan_from_scratch(problem, unused);
    fresh.stats.solve_time_s += spent;
    method = "batch after incremental";
    return fresh;
  }
  return plan;
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
  std::string method;
  bool threw = false;
  std::string error;
  try {
    plan = options_.incremental ? solve_incremental(problem, !replan, new_state, method)
                                : solve_batch(problem, replan, method);
  } catch (const std::exception& e) {
    threw = true;
    error = e.what();
    incremental_ready_ = false;
  }
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
    if (replan) ++counters_.replans;
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
    msg.method = method;
    spdlog::info("goal {}: plan {} {} ({}, {} iterations, {:.1f} ms)", goal.goal_id, plan_id,
                 plan.success() ? "valid" : "INVALID", msg.method, plan.stats.iterations,
                 plan.stats.solve_time_s * 1e3);
    if (plan.success()) last_plan_ = std::move(plan);
  }
  lcm_->publish(channel("PLAN"), &msg);
  publish_status();
}

void PlannerNode::worker_loop(const std::atomic<bool>& stop) {
  while (true) {
    std::optional<GoalRequest> goal;
    std::vector<ObstacleUpdate> updates;
    bool replace_all = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(50), [&] {
        return stop.load() || pending_goal_ || !pending_obstacles_.empty() || pending_replace_all_;
      });
      if (stop.load()) return;
      goal = std::move(pending_goal_);
      pending_goal_.reset();
      updates.swap(pending_obstacles_);
      replace_all = pending_replace_all_;
      pending_replace_all_ = false;
    }
    const bool obstacles_changed =
        (!updates.empty() || replace_all) && apply_obstacles(updates, replace_all);
    if (goal) {
      current_goal_ = goal;
      plan_and_publish(*goal, /*replan=*/false);
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
    if (lcm_->handleTimeout(50) < 0) {
      if (++handle_failures > 100) {
        spdlog::error("LCM handle failed 100 times in a row; stopping");
        break;
      }
      spdlog::debug("LCM handle failed once; continuing");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } else {
      handle_failures = 0;
    }
  }
  done = true;
  wake_.notify_all();
  worker.join();
}

}  // namespace kinograph::daemon
