#include "execute/executor_node.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>
#include <thread>

#include "kinograph/execution/stopping_trajectory.h"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/lcm/lcm_connection.h"
#include "kinograph/plan_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "kinograph/stop_request_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::execution {
namespace {

double wall_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

const ExecutorNodeOptions& checked(const ExecutorNodeOptions& o) {
  if (!(std::isfinite(o.rate_hz) && o.rate_hz >= 1 && o.rate_hz <= 10'000)) {
    throw std::invalid_argument("--rate must be in [1, 10000] Hz (setpoints per robot second)");
  }
  return o;
}

// Why a plan_t cannot be followed by this robot, or empty.
std::string unfit(const plan_t& msg, const dynamics::Model& model) {
  if (msg.clock != plan_t::CLOCK_ROBOT) {
    return "it is on the planner's wall clock (the planner had no robot state), not the robot's";
  }
  if (msg.num_joints != model.nq()) {
    return "it has " + std::to_string(msg.num_joints) + " joints, robot '" + model.name + "' has " +
           std::to_string(model.nq());
  }
  for (int j = 0; j < model.nq(); ++j) {
    if (msg.joint_name[j] != model.bodies[j].joint_name) {
      return "joint " + std::to_string(j) + " is '" + msg.joint_name[j] + "', robot '" +
             model.name + "' has '" + model.bodies[j].joint_name + "' there";
    }
  }
  if (msg.num_steps < 2) return "it has fewer than two knots";
  if (msg.start_utime < 0 || msg.takeover_utime < msg.start_utime) {
    return "its take-over (" + std::to_string(msg.takeover_utime) + " us) is before its start (" +
           std::to_string(msg.start_utime) + " us)";
  }
  for (int k = 0; k < msg.num_steps; ++k) {
    if (!std::isfinite(msg.t[k])) return "t[" + std::to_string(k) + "] is not finite";
    for (int j = 0; j < msg.num_joints; ++j) {
      if (!std::isfinite(msg.q[k][j]) || !std::isfinite(msg.qd[k][j]) ||
          !std::isfinite(msg.qdd[k][j]) || !std::isfinite(msg.tau[k][j])) {
        return "knot " + std::to_string(k) + " of joint '" + msg.joint_name[j] + "' is not finite";
      }
    }
  }
  return {};
}

}  // namespace

ExecutorNode::ExecutorNode(planning::Scene scene, ExecutorNodeOptions options, lcm::LCM* shared)
    : scene_(std::move(scene)), options_(checked(options)), schedule_(*scene_.problem.model) {
  identity_.model_name = scene_.problem.model->name;
  identity_.channel_prefix =
      messages::channel_prefix_or_default(options_.channel_prefix, identity_.model_name);
  lcm_ = messages::shared_or_open(shared, options_.lcm_url, owned_lcm_);
  subscriptions_ = {lcm_->subscribe(channel("PLAN"), &ExecutorNode::on_plan, this),
                    lcm_->subscribe(channel("STATE"), &ExecutorNode::on_state, this),
                    lcm_->subscribe(channel("STOP"), &ExecutorNode::on_stop, this)};
}

ExecutorNode::~ExecutorNode() {
  for (lcm::Subscription* s : subscriptions_) {
    if (s != nullptr) lcm_->unsubscribe(s);
  }
}

std::string ExecutorNode::channel(const std::string& suffix) const {
  return identity_.channel_prefix + "_" + suffix;
}

void ExecutorNode::on_plan(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  plan_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    ++counters_.plans_refused;
    spdlog::warn("{}: malformed plan_t not followed: {}", channel, s.reason);
    return;
  }
  if (!identity_.matches(msg.robot)) {
    ++counters_.plans_refused;
    spdlog::warn("{}: plan {} is for robot '{}', not '{}'; not followed", channel, msg.plan_id,
                 msg.robot, identity_.model_name);
    return;
  }
  if (msg.status != plan_t::SUCCESS || !msg.valid) {
    ++counters_.plans_ignored;
    spdlog::info("{}: plan {} failed (status {}), the motion under way continues", channel,
                 msg.plan_id, static_cast<int>(msg.status));
    return;
  }
  if (stopped_at_ >= 0 && msg.state_utime < stopped_at_) {
    ++counters_.plans_ignored;
    spdlog::info("{}: plan {} starts from a state measured before the stop at {} us; ignored",
                 channel, msg.plan_id, stopped_at_);
    return;
  }
  if (std::string why = unfit(msg, *scene_.problem.model); !why.empty()) {
    ++counters_.plans_refused;
    spdlog::warn("{}: plan {} not followed: {}", channel, msg.plan_id, why);
    return;
  }
  TimedPlan timed{msg.plan_id, msg.start_utime, msg.takeover_utime, msg.state_utime,
                  messages::plan_from_message(msg)};
  try {
    schedule_.add(std::move(timed));
  } catch (const std::invalid_argument& e) {
    ++counters_.plans_refused;
    spdlog::warn("{}: plan {} not followed: {}", channel, msg.plan_id, e.what());
    return;
  }
  ++counters_.plans_accepted;
  spdlog::debug("{}: plan {} queued to take over at {} us", channel, msg.plan_id,
                msg.takeover_utime);
}

void ExecutorNode::on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  robot_state_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    spdlog::warn("{}: malformed robot_state_t: {}", channel, s.reason);
    return;
  }
  if (!identity_.matches(msg.robot)) return;
  clock_.observe(msg.utime, wall_s());
}

void ExecutorNode::on_stop(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  stop_request_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    spdlog::warn("{}: malformed stop_request_t (stopping anyway): {}", channel, s.reason);
    msg.utime = 0;
  } else if (!identity_.matches(msg.robot)) {
    spdlog::warn("{}: stop request {} is for robot '{}', not '{}'; ignored", channel,
                 msg.request_id, msg.robot, identity_.model_name);
    return;
  } else {
    spdlog::warn("{}: stop request {} at {} us{}{}", channel, msg.request_id, msg.utime,
                 msg.reason.empty() ? "" : ": ", msg.reason);
  }
  // A stop is never refused: an unreadable one stops too, from its arrival. Plans from states
  // before the request are not followed from now on.
  pending_stop_ = msg.utime;
  stopped_at_ = std::max(stopped_at_, msg.utime);
}

void ExecutorNode::handle_pending() {
  while (lcm_->handleTimeout(0) > 0) {
  }
}

void ExecutorNode::carry_out_stop(int64_t utime) {
  ++counters_.stops;
  stopped_at_ = std::max(stopped_at_, utime);
  pending_stop_.reset();
  const std::optional<Setpoint> now = schedule_.at(utime);
  if (!now) return;  // nothing is moving: the robot holds its own state
  const dynamics::Model& model = *scene_.problem.model;
  StoppingTrajectory stop = stopping_trajectory(scene_.problem, now->q, now->qd, now->qdd);
  schedule_.clear();
  if (stop.valid) {
    spdlog::warn("stopping from plan {} at {} us: to rest in {} s", now->plan_id, utime,
                 stop.duration_s);
  } else {
    // Nothing within the limits stops the arm: hold where it is commanded to be, at rest.
    ++counters_.stops_unvalidated;
    spdlog::error("stopping from plan {} at {} us: {}; holding the commanded position",
                  now->plan_id, utime, stop.reason);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nq());
    stop.plan = linear_acceleration_plan(model, now->q, zero, {0, kShortestStopS}, {zero, zero}, 1);
  }
  schedule_.add(TimedPlan{-1, utime, utime, -1, std::move(stop.plan)});
}

bool ExecutorNode::publish_at(int64_t utime) {
  if (pending_stop_) carry_out_stop(utime);
  const std::optional<Setpoint> s = schedule_.at(utime);
  if (s) {
    messages::CommandSetpoint command{utime, s->plan_id, s->q, s->qd, s->tau};
    const joint_command_t msg = messages::command_to_message(command, *scene_.problem.model);
    lcm_->publish(channel("COMMAND"), &msg);
    ++counters_.commands;
  }
  // Logged after the command is sent: whoever reads the line knows the robot has it.
  const std::vector<Takeover>& switches = schedule_.takeovers();
  for (; takeovers_logged_ < switches.size(); ++takeovers_logged_) {
    const Takeover& t = switches[takeovers_logged_];
    spdlog::info("plan {} takes over from plan {} at {} us: jump {:.3g} rad, {:.3g} rad/s", t.to,
                 t.from, t.utime, t.jump_q, t.jump_qd);
  }
  return s.has_value();
}

void ExecutorNode::run(const std::atomic<bool>& stop) {
  spdlog::info("kinograph execute: robot {} following {} at {} Hz of its clock, commands on {}",
               identity_.model_name, channel("PLAN"), options_.rate_hz, channel("COMMAND"));
  const double period_robot_s = 1.0 / options_.rate_hz;
  double next = wall_s();
  int64_t last_sent = -1;
  while (!stop.load()) {
    // Messages are taken while waiting for the next tick, at most 10 ms at a time so that a
    // stop of the process is noticed.
    const double wait = next - wall_s();
    if (wait > 0) {
      lcm_->handleTimeout(std::max(1, std::min(10, static_cast<int>(std::ceil(wait * 1e3)))));
      handle_pending();
      continue;
    }
    handle_pending();
    const std::optional<int64_t> t = clock_.now(wall_s());
    if (t && *t != last_sent) {
      publish_at(*t);
      last_sent = *t;
    }
    // One tick per period of the robot's clock, however fast that runs against the wall.
    next += period_robot_s / clock_.rate();
    if (next < wall_s() - 1.0) next = wall_s();  // after a stall, no burst to catch up
  }
}

}  // namespace kinograph::execution
