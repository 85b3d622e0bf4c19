#include "daemon/neighbours.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/fleet/model_id.h"
#include "kinograph/fleet/neighbour_bodies.h"
#include "kinograph/graph/stopwatch.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::daemon {
namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

using graph::seconds_since;

}  // namespace

NeighbourSpec neighbour_from_option(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("--neighbour '" + text + "': expected NAME=SCENE[@PREFIX]");
  }
  NeighbourSpec spec;
  spec.name = text.substr(0, eq);
  std::string scene_path = text.substr(eq + 1);
  const std::size_t at = scene_path.rfind('@');
  if (at != std::string::npos) {
    spec.channel_prefix = scene_path.substr(at + 1);
    scene_path = scene_path.substr(0, at);
    if (spec.channel_prefix.empty() || scene_path.empty()) {
      throw std::invalid_argument("--neighbour '" + text + "': expected NAME=SCENE[@PREFIX]");
    }
  } else {
    spec.channel_prefix = upper(spec.name);
  }
  const planning::Scene scene = planning::load_scene(scene_path);
  spec.model = scene.problem.model;
  spec.start_q = scene.problem.start_q;
  spec.base = scene.base;
  return spec;
}

Neighbours::Neighbours(std::vector<NeighbourSpec> specs, std::string own_prefix,
                       NeighboursOptions options)
    : specs_(std::move(specs)), own_prefix_(std::move(own_prefix)), options_(options) {
  if (specs_.size() > static_cast<std::size_t>(kMaxNeighbours)) {
    throw std::invalid_argument("at most " + std::to_string(kMaxNeighbours) + " neighbours, got " +
                                std::to_string(specs_.size()));
  }
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const NeighbourSpec& s = specs_[i];
    if (!s.model) throw std::invalid_argument("neighbour '" + s.name + "' has no robot model");
    if (s.model->collision.size() > static_cast<std::size_t>(kMaxBodies)) {
      throw std::invalid_argument("neighbour '" + s.name + "' has more than " +
                                  std::to_string(kMaxBodies) + " collision geometries");
    }
    if (s.channel_prefix == own_prefix_) {
      throw std::invalid_argument("neighbour '" + s.name + "' uses this robot's own channels " +
                                  own_prefix_ + "_*");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (specs_[j].name == s.name || specs_[j].channel_prefix == s.channel_prefix) {
        throw std::invalid_argument("neighbour '" + s.name + "' is named twice (name or prefix)");
      }
    }
    model_ids_.push_back(fleet::model_id(*s.model));
  }
  heard_.resize(specs_.size());
}

void Neighbours::subscribe(lcm::LCM& lcm, std::function<void()> changed) {
  changed_callback_ = std::move(changed);
  // Queue sizes: one plan is ~25 kB and only the newest counts; states come at up to 1 kHz.
  const struct {
    const char* suffix;
    void (Neighbours::*handler)(std::size_t, const lcm::ReceiveBuffer*);
    int capacity;
  } kinds[] = {{"_PLAN", &Neighbours::on_plan, 20},
               {"_PLAN_CURRENT", &Neighbours::on_plan, 20},
               {"_STATE", &Neighbours::on_state, 2000},
               {"_PLANNER_STATUS", &Neighbours::on_heartbeat, 100}};
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    for (const auto& kind : kinds) {
      routes_.push_back(std::make_unique<Route>(Route{this, i, kind.handler}));
      lcm::Subscription* s = lcm.subscribeFunction(
          specs_[i].channel_prefix + kind.suffix,
          +[](const lcm::ReceiveBuffer* rbuf, const std::string&, Route* r) {
            (r->self->*(r->handler))(r->index, rbuf);
          },
          routes_.back().get());
      s->setQueueCapacity(kind.capacity);
      subscriptions_.push_back(s);
    }
  }
}

void Neighbours::unsubscribe(lcm::LCM& lcm) {
  for (lcm::Subscription* s : subscriptions_) lcm.unsubscribe(s);
  subscriptions_.clear();
}

void Neighbours::notify() {
  if (changed_callback_) changed_callback_();
}

void Neighbours::on_plan(std::size_t i, const lcm::ReceiveBuffer* rbuf) {
  plan_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    spdlog::warn("neighbour '{}': malformed plan_t: {}", specs_[i].name, s.reason);
    return;
  }
  // A failure answer leaves the neighbour on the plan it had.
  if (msg.status != plan_t::SUCCESS || msg.num_steps < 2) return;
  const dynamics::Model& model = *specs_[i].model;
  bool order_ok = msg.num_joints == model.nq();
  for (int j = 0; order_ok && j < model.nq(); ++j) {
    order_ok = msg.joint_name[j] == model.bodies[j].joint_name;
  }
  if (!order_ok) {
    std::lock_guard lock(mutex_);
    heard_[i].mismatch =
        "its plans' joints are not those of its scene's robot '" + model.name + "'";
    return;
  }
  planning::Plan plan = messages::plan_from_message(msg);
  {
    std::lock_guard lock(mutex_);
    Heard& h = heard_[i];
    // The current plan sent again (for a robot that joined late) is no change.
    if (h.plan && h.plan_id == msg.plan_id && h.plan_start_utime == msg.start_utime) return;
    h.plan = std::move(plan);
    h.plan_start_utime = msg.start_utime;
    h.plan_id = msg.plan_id;
    ++h.generation;
    changed_ = true;
  }
  notify();
}

void Neighbours::on_state(std::size_t i, const lcm::ReceiveBuffer* rbuf) {
  robot_state_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    return;
  }
  messages::RobotIdentity identity{specs_[i].model->name, specs_[i].channel_prefix};
  messages::MeasuredState state;
  if (!messages::state_from_message(msg, *specs_[i].model, identity, state).ok ||
      !state.q.allFinite()) {
    return;
  }
  bool woke = false;
  {
    std::lock_guard lock(mutex_);
    Heard& h = heard_[i];
    h.state = state.q;
    h.state_utime = msg.utime;
    h.last_heard = std::chrono::steady_clock::now();
    if (h.silent) {
      h.silent = false;
      changed_ = woke = true;
    }
  }
  if (woke) notify();
}

void Neighbours::on_heartbeat(std::size_t i, const lcm::ReceiveBuffer* rbuf) {
  planner_status_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    std::lock_guard lock(mutex_);
    heard_[i].mismatch = "its heartbeat is not a planner_status_t of version 4: " + s.reason;
    return;
  }
  std::string mismatch;
  if (msg.model_id != model_ids_[i]) {
    mismatch = "its model is " + msg.model_id + ", its scene's is " + model_ids_[i];
  } else {
    Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
    base.translation() =
        Eigen::Vector3d(msg.base_position[0], msg.base_position[1], msg.base_position[2]);
    base.linear() = Eigen::Quaterniond(msg.base_quaternion[0], msg.base_quaternion[1],
                                       msg.base_quaternion[2], msg.base_quaternion[3])
                        .normalized()
                        .toRotationMatrix();
    mismatch = fleet::base_mismatch(specs_[i].base, base);
  }
  const std::int64_t goal_utime =
      msg.goal_utime < 0 ? std::numeric_limits<std::int64_t>::max() : msg.goal_utime;
  bool changed = false, planning_changed = false;
  {
    std::lock_guard lock(mutex_);
    Heard& h = heard_[i];
    if (mismatch != h.mismatch && !mismatch.empty()) {
      spdlog::warn("neighbour '{}': {}", specs_[i].name, mismatch);
    }
    h.mismatch = mismatch;
    if (!h.last_heard || h.silent) joined_ = true;
    h.last_heard = std::chrono::steady_clock::now();
    const std::string blocked_by = fleet::blocker_prefix(msg.message);
    // A neighbour newly blocked, by this robot or by one that may be in a cycle through it, may
    // make this robot's failure a deadlock.
    changed = h.silent || h.goal_utime != goal_utime ||
              (blocked_by != h.blocked_by && !blocked_by.empty());
    h.silent = false;
    h.goal_utime = goal_utime;
    h.blocked_by = blocked_by;
    changed_ = changed_ || changed;
    // Not a change of what is planned around, but a robot yielding to it waits for this.
    planning_changed = h.planning_goal_utime != msg.planning_goal_utime;
    h.planning_goal_utime = msg.planning_goal_utime;
  }
  if (changed || planning_changed) notify();
}

bool Neighbours::update_silence_locked() {
  bool any = false;
  for (std::size_t i = 0; i < heard_.size(); ++i) {
    Heard& h = heard_[i];
    if (!h.silent && h.last_heard && seconds_since(*h.last_heard) > options_.timeout_s) {
      h.silent = true;
      any = true;
      spdlog::warn("neighbour '{}': silent for {} s, held at its last known state", specs_[i].name,
                   options_.timeout_s);
    }
  }
  return any;
}

bool Neighbours::take_changed() {
  std::lock_guard lock(mutex_);
  const bool silence = update_silence_locked();
  const bool changed = changed_ || silence;
  changed_ = false;
  return changed;
}

std::string Neighbours::planning_above(std::int64_t own_goal_utime) const {
  std::lock_guard lock(mutex_);
  const fleet::PriorityKey own{own_goal_utime, own_prefix_};
  std::optional<std::size_t> highest;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const Heard& h = heard_[i];
    const bool heard_lately = h.last_heard && seconds_since(*h.last_heard) <= options_.timeout_s;
    if (h.planning_goal_utime < 0 || !heard_lately) continue;
    const fleet::PriorityKey key{h.planning_goal_utime, specs_[i].channel_prefix};
    if (!fleet::outranks(key, own)) continue;
    if (!highest || fleet::outranks(key, {heard_[*highest].planning_goal_utime,
                                          specs_[*highest].channel_prefix})) {
      highest = i;
    }
  }
  return highest ? specs_[*highest].name : std::string();
}

bool Neighbours::take_joined() {
  std::lock_guard lock(mutex_);
  const bool joined = joined_;
  joined_ = false;
  return joined;
}

fleet::Decision Neighbours::decide(const fleet::PriorityKey& own, bool own_goal_changed) {
  std::vector<fleet::NeighbourView> views;
  std::lock_guard lock(mutex_);
  update_silence_locked();
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const Heard& h = heard_[i];
    fleet::NeighbourView v;
    v.name = specs_[i].name;
    v.key = {h.goal_utime, specs_[i].channel_prefix};
    if (h.plan) v.plan_id = h.generation;
    v.silent = h.silent;
    views.push_back(std::move(v));
  }
  fleet::PriorityKey key = own;
  key.robot = own_prefix_;
  if (own_goal_changed) {
    blocked_goal_.reset();
    goal_retries_ = 0;
  }
  if (blocked_goal_) blocked_goal_->retries = goal_retries_;
  return fleet::coordinate(key, views, tried_, own_goal_changed,
                           blocked_goal_ ? &*blocked_goal_ : nullptr);
}

void Neighbours::add_obstacles(const fleet::Decision& decision, std::int64_t origin_utime,
                               std::vector<collision::Obstacle>& obstacles) {
  std::lock_guard lock(mutex_);
  ++rebuilds_;
  body_names_.clear();
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const Heard& h = heard_[i];
    const fleet::Neighbour n{specs_[i].name, specs_[i].model};
    const int slot = static_cast<int>(i) * kMaxBodies;
    std::vector<fleet::NeighbourBody> bodies;
    if (const planning::Plan* followed = followed_plan_locked(decision, i)) {
      // Moving bodies get new ids every time: the planner keeps a moving obstacle whose id it
      // knows, so a new plan of the neighbour must come as new obstacles.
      const int first = kFirstObstacleId + (1 << 20) +
                        static_cast<int>(rebuilds_ % 1000) * kMaxNeighbours * kMaxBodies + slot;
      bodies =
          fleet::bodies_along(n, *followed, fleet::clock_offset(h.plan_start_utime, origin_utime),
                              fleet::SweepOptions{.first_id = first});
    } else if (const std::optional<Eigen::VectorXd> q = held_q_locked(i, origin_utime)) {
      bodies = fleet::bodies_at(n, *q, kFirstObstacleId + slot);
    }
    for (fleet::NeighbourBody& b : bodies) {
      body_names_[b.obstacle.id] = b.name;
      obstacles.push_back(std::move(b.obstacle));
    }
  }
}

const planning::Plan* Neighbours::followed_plan_locked(const fleet::Decision& decision,
                                                       std::size_t i) const {
  const Heard& h = heard_[i];
  if (decision.treatment[i] != fleet::Treatment::kAlongPlan || !h.plan) return nullptr;
  const std::int64_t end = h.plan_start_utime + std::llround(h.plan->t.back() * 1e6);
  if (h.state && h.state_utime > end) return nullptr;
  return &*h.plan;
}

std::optional<Eigen::VectorXd> Neighbours::held_q_locked(std::size_t i, std::int64_t utime) const {
  const Heard& h = heard_[i];
  if (h.state) return h.state;
  // Heard a plan but no state: it is where that plan has it (a daemon without states moves along
  // its plans, and its next plan, around this robot's, starts from there).
  if (h.plan) {
    planning::TrajectorySampler sampler(*specs_[i].model, *h.plan);
    return fleet::held_configuration(*h.plan, sampler,
                                     fleet::clock_offset(utime, h.plan_start_utime));
  }
  // Nothing heard yet: it stands at its scene's start.
  if (specs_[i].start_q.size() == specs_[i].model->nq()) return specs_[i].start_q;
  return std::nullopt;
}

std::optional<fleet::Blocker> Neighbours::blocker(const fleet::Decision& decision,
                                                  std::int64_t origin_utime,
                                                  const dynamics::Model& own_model,
                                                  const planning::Plan& plan, double wait_s,
                                                  double contact, double from_s,
                                                  std::string& why) const {
  if (plan.q.rows() < 2) return std::nullopt;
  // The own model as the fleet check wants it: shared, without owning it.
  const std::shared_ptr<const dynamics::Model> own(std::shared_ptr<void>(), &own_model);
  const fleet::RobotPlan self{own_prefix_, own, plan, wait_s};
  // Each neighbour as the decision treats it, copied under the lock; checked outside it, so that
  // the LCM thread's handlers are not held up.
  std::vector<std::pair<fleet::RobotPlan, fleet::Blocker>> others;
  {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < specs_.size(); ++i) {
      const Heard& h = heard_[i];
      fleet::RobotPlan other{specs_[i].name, specs_[i].model, {}, 0.0};
      fleet::Blocker b{specs_[i].name, specs_[i].channel_prefix, decision.treatment[i], 0.0,
                       false, blocking_cycle_locked(i)};
      b.blocked_by_own = !b.cycle.empty();
      if (const planning::Plan* followed = followed_plan_locked(decision, i)) {
        other.plan = *followed;
        other.offset = fleet::clock_offset(h.plan_start_utime, origin_utime);
        b.plan_end = other.offset + h.plan->t.back();
      } else if (const std::optional<Eigen::VectorXd> q =
                     held_q_locked(i, origin_utime + std::llround(wait_s * 1e6))) {
        other.plan = fleet::standing_plan(*q);
        b.treatment = fleet::Treatment::kHeldAtState;
        // Without a measured state it goes on along its plan in force (held_q_locked): a wait
        // for that plan's end finds it standing there.
        if (!h.state && h.plan) {
          b.moving = true;
          b.plan_end = fleet::clock_offset(h.plan_start_utime, origin_utime) + h.plan->t.back();
        }
      } else {
        continue;
      }
      others.emplace_back(std::move(other), std::move(b));
    }
  }
  std::optional<fleet::Blocker> found;
  double closest = contact;
  for (const auto& [other, b] : others) {
    const fleet::JointClearance c = fleet::joint_clearance({self, other}, {.from = from_s});
    if (c.min_distance >= closest) continue;
    closest = c.min_distance;
    why = fleet::describe(c);
    found = b;
  }
  return found;
}

std::vector<std::string> Neighbours::blocking_cycle(const std::string& name) const {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    if (specs_[i].name == name) return blocking_cycle_locked(i);
  }
  return {};
}

std::vector<std::string> Neighbours::blocking_cycle_locked(std::size_t i) const {
  // Each neighbour's heartbeat names its blocker; follow them until this robot, someone unknown
  // or not blocked, or a robot seen before (a cycle without this robot: not its deadlock).
  std::vector<std::string> chain;
  std::vector<bool> seen(specs_.size(), false);
  for (std::size_t at = i;;) {
    if (seen[at]) return {};
    seen[at] = true;
    chain.push_back(specs_[at].channel_prefix);
    const std::string& next = heard_[at].blocked_by;
    if (next == own_prefix_) return chain;
    std::size_t n = 0;
    while (n < specs_.size() && specs_[n].channel_prefix != next) ++n;
    if (next.empty() || n == specs_.size()) return {};
    at = n;
  }
}

void Neighbours::planned(const fleet::Decision& decision, bool valid,
                         const fleet::Blocker* refused_by) {
  std::lock_guard lock(mutex_);
  tried_ = decision.around;
  if (valid) planned_ = decision.around;
  if (decision.retry) ++goal_retries_;
  blocked_goal_.reset();
  if (!refused_by) return;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    // The blocker's plan as the decision saw it: one that came while planning is a new one.
    if (specs_[i].name == refused_by->name) {
      blocked_goal_ = fleet::BlockedGoal{refused_by->name, decision.plans[i], goal_retries_};
    }
  }
}

std::string Neighbours::name_bodies(std::string text) const {
  static const std::regex kObstacleId("obstacle (\\d+)");
  std::lock_guard lock(mutex_);
  std::string out;
  auto begin = std::sregex_iterator(text.begin(), text.end(), kObstacleId);
  std::size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const auto found = body_names_.find(std::stoi((*it)[1].str()));
    if (found == body_names_.end()) continue;
    out += text.substr(last, it->position() - last) + found->second;
    last = it->position() + it->length();
  }
  return out + text.substr(last);
}

std::string Neighbours::summary() const {
  std::lock_guard lock(mutex_);
  std::ostringstream os;
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const Heard& h = heard_[i];
    if (i > 0) os << "; ";
    os << specs_[i].name << ": ";
    if (!h.last_heard && !h.plan) {
      os << "not heard yet";
    } else if (h.silent) {
      os << "silent for " << seconds_since(*h.last_heard) << " s, held at its last state";
    } else if (h.plan) {
      os << "plan " << h.plan_id;
      const auto it = planned_.find(specs_[i].name);
      // What the own valid plan was made around: this plan, an older one, or it standing.
      const bool around_plan = it != planned_.end() && it->second != fleet::kHeldMark;
      os << (around_plan && it->second == h.generation ? ", followed"
             : around_plan                             ? ", an earlier plan followed"
                                                       : ", held at its state");
    } else {
      os << "no plan, held at its state";
    }
    if (!h.mismatch.empty()) os << " (" << h.mismatch << ")";
  }
  return os.str();
}

}  // namespace kinograph::daemon
