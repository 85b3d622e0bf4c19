#include "sim/sim_node.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>
#include <thread>

#include "drake/lcmt_iiwa_status.hpp"
#include "kinograph/lcm/lcm_connection.h"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::sim {
namespace {

int64_t wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

const SimNodeOptions& checked(const SimNodeOptions& o) {
  if (!(std::isfinite(o.slowdown) && o.slowdown >= 1e-3 && o.slowdown <= 1e3)) {
    throw std::invalid_argument("--slowdown must be in [0.001, 1000] (wall s per simulated s)");
  }
  if (o.start_utime < -1) {
    throw std::invalid_argument("--start-utime must be >= 0 us (or -1: the wall clock)");
  }
  if (!(std::isfinite(o.duration_s) && o.duration_s >= 0)) {
    throw std::invalid_argument("--duration must be >= 0 s");
  }
  if (!std::isfinite(o.payload_mass_error_kg)) {
    throw std::invalid_argument("--payload-mass-error must be finite");
  }
  return o;
}

// The plant the simulator moves: the model with the payload error, refused under the option's
// name.
dynamics::Model plant_for(const dynamics::Model& model, double payload_mass_error_kg) {
  try {
    return with_last_body_mass_change(model, payload_mass_error_kg);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--payload-mass-error: ") + e.what());
  }
}

std::vector<double> to_vector(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

}  // namespace

double TrackingStats::rms() const {
  return samples > 0 ? std::sqrt(sum_sq / static_cast<double>(samples)) : 0.0;
}

void TrackingStats::add(double error) {
  max = std::max(max, error);
  sum_sq += error * error;
  ++samples;
}

SimNode::SimNode(planning::Scene scene, SimNodeOptions options, lcm::LCM* shared)
    : scene_(std::move(scene)),
      options_(checked(options)),
      plant_(plant_for(*scene_.problem.model, options_.payload_mass_error_kg)),
      noise_(options_.position_noise, options_.velocity_noise, options_.seed) {
  const dynamics::Model& model = *scene_.problem.model;
  identity_.model_name = model.name;
  identity_.channel_prefix =
      messages::channel_prefix_or_default(options_.channel_prefix, model.name);
  data_ = std::make_unique<dynamics::Data>(model);
  sim_ = std::make_unique<RigidBodySim>(plant_);
  state_ = {scene_.problem.start_q, scene_.problem.start_qd};
  // Gains and the first hold come from the model the planner knows, not from the plant; the
  // gains are shaped by the mass matrix at each new setpoint.
  gains_ = gains_for(model, *data_, state_.q, kPdFrequencyHz, kDampingRatio);
  setpoint_ = hold_setpoint(model, *data_, state_.q);
  lcm_ = messages::shared_or_open(shared, options_.lcm_url, owned_lcm_);
  subscription_ = lcm_->subscribe(channel("COMMAND"), &SimNode::on_command, this);
}

SimNode::~SimNode() {
  if (subscription_ != nullptr) lcm_->unsubscribe(subscription_);
}

std::string SimNode::channel(const std::string& suffix) const {
  return identity_.channel_prefix + "_" + suffix;
}

void SimNode::on_command(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  joint_command_t msg;
  messages::CommandSetpoint command;
  std::string why;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    why = "malformed joint_command_t: " + s.reason;
  } else if (messages::Check c =
                 messages::command_from_message(msg, *scene_.problem.model, identity_, command);
             !c.ok) {
    why = c.reason;
  }
  if (!why.empty()) {
    ++rejected_;
    spdlog::warn("{}: command refused, holding the last one: {}", channel, why);
    return;
  }
  ++commands_;
  gains_ = gains_for(*scene_.problem.model, *data_, command.q, kPdFrequencyHz, kDampingRatio);
  setpoint_ = {std::move(command.q), std::move(command.qd), std::move(command.tau)};
}

double SimNode::tracking_error() const { return (setpoint_.q - state_.q).cwiseAbs().maxCoeff(); }

void SimNode::publish_state(int64_t utime) {
  Eigen::VectorXd q = state_.q, qd = state_.qd;
  noise_.apply(q, qd);
  const dynamics::Model& model = *scene_.problem.model;
  robot_state_t msg;
  msg.utime = utime;
  msg.robot = model.name;
  msg.num_joints = model.nq();
  for (const auto& body : model.bodies) msg.joint_name.push_back(body.joint_name);
  msg.position = to_vector(q);
  msg.velocity = to_vector(qd);
  lcm_->publish(channel("STATE"), &msg);
  if (options_.iiwa_status_channel.empty()) return;
  // Drake's driver reports what it measured and what it was told; the plant has no sensor of
  // external torque.
  const Eigen::VectorXd tau = sim_->torque(gains_, setpoint_, state_);
  drake::lcmt_iiwa_status status;
  status.utime = utime;
  status.num_joints = model.nq();
  status.joint_position_measured = msg.position;
  status.joint_velocity_estimated = msg.velocity;
  status.joint_position_commanded = to_vector(setpoint_.q);
  status.joint_position_ipo = status.joint_position_commanded;
  status.joint_torque_measured = to_vector(tau);
  status.joint_torque_commanded = status.joint_torque_measured;
  status.joint_torque_external.assign(model.nq(), 0.0);
  lcm_->publish(options_.iiwa_status_channel, &status);
}

void SimNode::run(const std::atomic<bool>& stop) {
  const int64_t start_utime = options_.start_utime >= 0 ? options_.start_utime : wall_utime();
  spdlog::info(
      "kinograph sim: robot {} on channels {}_STATE and {}_COMMAND, clock from {} us, "
      "{}x slower than the wall clock",
      identity_.model_name, identity_.channel_prefix, identity_.channel_prefix, start_utime,
      options_.slowdown);
  const auto wall_start = std::chrono::steady_clock::now();
  const long steps_per_log = std::lround(kLogPeriodS / kStepS);
  const long last_step = options_.duration_s > 0 ? std::lround(options_.duration_s / kStepS) : -1;
  for (long step = 0; !stop.load(); ++step) {
    // Commands that arrived are applied before the next step; the last one is held.
    while (lcm_->handleTimeout(0) > 0) {
    }
    if (step % kStepsPerState == 0) {
      const double error = tracking_error();
      total_.add(error);
      window_.add(error);
      publish_state(start_utime + std::llround(static_cast<double>(step) * kStepS * 1e6));
    }
    if (step > 0 && step % steps_per_log == 0) {
      spdlog::info(
          "sim {:.3f} s: tracking error over the last {:.0f} s max {:.3g} rad, rms "
          "{:.3g} rad",
          static_cast<double>(step) * kStepS, kLogPeriodS, window_.max, window_.rms());
      window_ = {};
    }
    if (step == last_step) break;
    try {
      sim_->step(kStepS, gains_, setpoint_, state_);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("at simulated time " +
                               std::to_string(static_cast<double>(step) * kStepS) +
                               " s: " + e.what());
    }
    // The simulated time may fall behind the wall clock on a busy machine, never run ahead.
    std::this_thread::sleep_until(wall_start +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(static_cast<double>(step + 1) *
                                                                    kStepS * options_.slowdown)));
  }
}

}  // namespace kinograph::sim
