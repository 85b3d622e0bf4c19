#include "daemon/planner_node.h"

#include <poll.h>
#include <unistd.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <utility>

#include "daemon/robot_payload.h"
#include "daemon/state_file.h"
#include "daemon/state_limits.h"
#include "daemon/wire_strings.h"
#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/fleet/model_id.h"
#include "kinograph/graph/cancellation.h"
#include "kinograph/graph/stopwatch.h"
#include "kinograph/lcm/drake_convert.h"
#include "kinograph/lcm/lcm_connection.h"
#include "kinograph/payload_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "lcmtypes/safe_decode.h"

namespace kinograph::daemon {
namespace {

const dynamics::Model& robot_of(const planning::Scene& scene) {
  if (!scene.problem.model) throw std::invalid_argument("PlannerNode: the scene has no robot");
  return *scene.problem.model;
}

}  // namespace

namespace {
// Why a goal got CANCELLED: a solve cut short, or a goal never started.
constexpr char kShutdownReason[] = "the planner daemon is shutting down";

// An obstacle as messages name it: "id", or "id" of source "s" (bounded, wire_strings.h).
std::string obstacle_name(const ObstacleKey& key) {
  std::string name = "\"" + truncated(key.second) + "\"";
  if (!key.first.empty()) name += " of source \"" + truncated(key.first) + "\"";
  return name;
}

// Waits up to `timeout_ms` until `fd` (-1: none) or `wake_fd` (-1: none) is readable; true
// when `fd` is. A signal interrupting the wait ends it too (false).
bool wait_readable(int fd, int wake_fd, int timeout_ms) {
  pollfd fds[2] = {{fd, POLLIN, 0}, {wake_fd, POLLIN, 0}};
  return poll(fds, 2, timeout_ms) > 0 && (fds[0].revents & (POLLIN | POLLERR | POLLHUP)) != 0;
}
}  // namespace

PlannerNode::PlannerNode(planning::Scene scene, PlannerNodeOptions options, lcm::LCM* shared)
    : scene_(std::move(scene)),
      options_(std::move(options)),
      motion_join_(robot_of(scene_), options_.takeover_latency_s),
      planned_motion_(robot_of(scene_)),
      replanner_(options_.replanning) {
  identity_.model_name = scene_.problem.model->name;
  identity_.channel_prefix =
      messages::channel_prefix_or_default(options_.channel_prefix, identity_.model_name);
  lcm_ = messages::shared_or_open(shared, options_.lcm_url, owned_lcm_);
  next_obstacle_id_ = static_cast<int>(scene_.problem.obstacles.size());
  for (const auto& o : scene_.problem.obstacles) {
    next_obstacle_id_ = std::max(next_obstacle_id_, o.id + 1);
  }
  // Before subscribing: a state file refused leaves nothing subscribed on a shared LCM.
  restore_state();
  subscriptions_ = {lcm_->subscribe(channel("GOAL"), &PlannerNode::on_goal, this),
                    lcm_->subscribe(channel("OBSTACLES"), &PlannerNode::on_obstacles, this),
                    lcm_->subscribe(channel("STATE"), &PlannerNode::on_state, this)};
  subscriptions_.push_back(
      lcm_->subscribe(channel("PLANNER_STATUS"), &PlannerNode::on_heartbeat, this));
  subscriptions_.push_back(lcm_->subscribe(channel("COMMAND"), &PlannerNode::on_command, this));
  subscriptions_.push_back(lcm_->subscribe(channel("PAYLOAD"), &PlannerNode::on_payload, this));
  std::vector<int> capacities = {kGoalQueueCapacity,  kObstacleQueueCapacity,
                                 kStateQueueCapacity, kHeartbeatQueueCapacity,
                                 kStateQueueCapacity, kPayloadQueueCapacity};
  if (!options_.iiwa_status_channel.empty()) {
    subscriptions_.push_back(
        lcm_->subscribe(options_.iiwa_status_channel, &PlannerNode::on_iiwa_status, this));
    capacities.push_back(kStateQueueCapacity);
  }
  for (std::size_t i = 0; i < subscriptions_.size(); ++i) {
    subscriptions_[i]->setQueueCapacity(capacities[i]);
  }
  model_id_ = fleet::model_id(*scene_.problem.model);
  if (!options_.neighbours.empty()) {
    neighbours_ = std::make_unique<Neighbours>(options_.neighbours, identity_.channel_prefix,
                                               options_.neighbour_watch);
    neighbours_->subscribe(*lcm_, [this] { wake_.notify_one(); });
  }
}

void PlannerNode::restore_state() {
  if (options_.state_file.empty()) {
    spdlog::info(
        "kinographd: no --state-file: plan ids start at 1, and obstacles received over LCM are "
        "forgotten when the daemon stops");
    return;
  }
  if (!std::ifstream(options_.state_file)) {
    spdlog::info(
        "kinographd: state file {} does not exist yet: plan ids start at 1, no "
        "obstacles from LCM",
        options_.state_file);
  } else {
    DaemonState state =
        read_state_file(options_.state_file, identity_.model_name, identity_.channel_prefix);
    const std::size_t world = scene_.problem.obstacles.size() + state.obstacles.size();
    if (world > static_cast<std::size_t>(collision::kMaxObstacles)) {
      throw StateFileError("state file '" + options_.state_file + "': its " +
                           std::to_string(state.obstacles.size()) + " obstacles and the scene's " +
                           std::to_string(scene_.problem.obstacles.size()) + " are more than the " +
                           std::to_string(collision::kMaxObstacles) + " a world may hold");
    }
    next_plan_id_ = state.plan_ids_below;
    for (const auto& [key, u] : state.obstacles) {
      collision::Obstacle o;
      o.id = next_obstacle_id_++;
      o.shape = u.shape;
      o.pose = u.pose;
      live_obstacles_[key] = std::move(o);
    }
    stored_obstacles_ = std::move(state.obstacles);
    spdlog::info(
        "kinographd: state file {}: plan ids from {}, {} obstacles received over LCM "
        "before the restart",
        options_.state_file, next_plan_id_, stored_obstacles_.size());
  }
  // The file is ours from now on: a reservation is written before the first id is used.
  plan_ids_reserved_ = next_plan_id_;
}

int64_t PlannerNode::take_plan_id_locked() {
  if (!options_.state_file.empty() && next_plan_id_ >= plan_ids_reserved_) {
    plan_ids_reserved_ = next_plan_id_ + kPlanIdReservation;
    save_state_locked();
  }
  return next_plan_id_++;
}

void PlannerNode::save_state_locked() {
  if (options_.state_file.empty()) return;
  DaemonState state;
  state.robot = identity_.model_name;
  state.prefix = identity_.channel_prefix;
  state.plan_ids_below = std::max(plan_ids_reserved_, next_plan_id_);
  state.obstacles = stored_obstacles_;
  try {
    write_state_file(options_.state_file, state);
    stored_obstacles_dirty_ = false;
    state_written_at_ = std::chrono::steady_clock::now();
  } catch (const StateFileError& e) {
    spdlog::error("{}: plan ids and obstacles will not survive a restart", e.what());
  }
}

// A shared LCM instance outlives the node: its handlers must not call into a destroyed node.
PlannerNode::~PlannerNode() {
  if (neighbours_) neighbours_->unsubscribe(*lcm_);
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

int64_t PlannerNode::wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

messages::PlanTime PlannerNode::clock_now_locked() const {
  messages::PlanTime time;
  if (latest_state_) {
    time.clock = plan_t::CLOCK_ROBOT;
    time.utime = latest_state_->utime;
  } else {
    time.clock = plan_t::CLOCK_WALL;
    time.utime = wall_utime();
  }
  return time;
}

std::string PlannerNode::stale_state_reason(const std::string& what, int64_t utime,
                                            const MeasuredState& state) const {
  const double age_s = static_cast<double>(utime - state.utime) * 1e-6;
  if (age_s <= options_.max_state_age_s) return {};
  return "the latest measured state (utime " + std::to_string(state.utime) + " us) is " +
         std::to_string(age_s) + " s older than " + what + " (utime " + std::to_string(utime) +
         " us), more than the " + std::to_string(options_.max_state_age_s) +
         " s allowed (--max-state-age): has the robot's state stream stopped, or are the message "
         "and the states on different clocks?";
}

void PlannerNode::reject(const std::string& channel, const std::string& reason) {
  bool log;
  std::vector<std::string> summaries;
  {
    std::lock_guard lock(mutex_);
    ++counters_.messages_rejected;
    last_message_ = reason;
    log = reject_log_.admit(channel, LogLimiter::Clock::now(), summaries);
  }
  for (const std::string& line : summaries) spdlog::warn("{}", line);
  if (log) spdlog::warn("rejected: {}", reason);
  publish_status();
}

void PlannerNode::flush_reject_log() {
  std::vector<std::string> summaries;
  {
    std::lock_guard lock(mutex_);
    summaries = reject_log_.flush(LogLimiter::Clock::now());
  }
  for (const std::string& line : summaries) spdlog::warn("{}", line);
}

template <class Message>
void PlannerNode::publish(const std::string& channel, const Message& msg) {
  std::vector<uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  publish_bytes(Message::getTypeName(), channel, bytes.data(), static_cast<unsigned>(bytes.size()));
}

void PlannerNode::publish_bytes(const char* type, const std::string& channel, const void* data,
                                unsigned size) {
  const int status = lcm_->publish(channel, data, size);
  if (status == 0) return;
  int64_t failures;
  {
    std::lock_guard lock(mutex_);
    failures = ++counters_.publish_failures;
    last_publish_failure_ = channel;
  }
  spdlog::error("publishing {} on {} failed (LCM returned {}); {} publishes failed since start",
                type, channel, status, failures);
}

void PlannerNode::answer_with_failure(int8_t status, const std::string& reason, int64_t goal_id,
                                      bool first_answer) {
  int64_t plan_id;
  messages::PlanTime time;
  {
    std::lock_guard lock(mutex_);
    plan_id = take_plan_id_locked();
    ++counters_.plans_published;
    ++counters_.failures;
    if (first_answer) ++counters_.goals_answered;
    if (status == plan_t::SUPERSEDED) ++counters_.goals_superseded;
    if (status == plan_t::CANCELLED && first_answer) ++counters_.goals_cancelled;
    time = clock_now_locked();
    if (latest_state_) time.state_utime = latest_state_->utime;
  }
  plan_t answer =
      messages::failure_message(status, reason, identity_.model_name, plan_id, goal_id, time);
  publish(channel("PLAN"), answer);
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

namespace {

// Bounds the names of a decoded goal of any version, then converts it.
template <typename GoalMessage>
Check convert_goal(const GoalMessage& msg, const dynamics::Model& model,
                   const RobotIdentity& identity, GoalRequest& request) {
  // Names are bounded first, so that no reason echoes an unbounded string.
  if (std::string overlong = overlong_name(msg); !overlong.empty()) return Check::fail(overlong);
  return messages::goal_from_message(msg, model, identity, request);
}

// A goal of one of the versions sharing the channel, decoded: its id (-1 when it did not
// decode) and its conversion, run once the goal is counted.
struct DecodedGoal {
  std::string malformed;  // why it did not decode, or empty
  int64_t goal_id = -1;
  std::function<Check(const dynamics::Model&, const RobotIdentity&, GoalRequest&)> convert;
};

template <typename GoalMessage>
DecodedGoal decode_goal(const char* type, const lcm::ReceiveBuffer* rbuf) {
  auto msg = std::make_shared<GoalMessage>();
  DecodedGoal out;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), *msg); !s.ok) {
    out.malformed = std::string("malformed ") + type + ": " + s.reason;
    return out;
  }
  out.goal_id = msg->goal_id;
  out.convert = [msg](const dynamics::Model& model, const RobotIdentity& identity,
                      GoalRequest& request) {
    return convert_goal(*msg, model, identity, request);
  };
  return out;
}

}  // namespace

void PlannerNode::on_goal(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // The goal versions share the channel; the fingerprint says which one came.
  const int size = static_cast<int>(rbuf->data_size);
  DecodedGoal decoded;
  if (lcmtypes::has_fingerprint<goal_t>(rbuf->data, size)) {
    decoded = decode_goal<goal_t>("goal_t", rbuf);
  } else if (lcmtypes::has_fingerprint<goal_v2_t>(rbuf->data, size)) {
    decoded = decode_goal<goal_v2_t>("goal_v2_t", rbuf);
  } else if (lcmtypes::has_fingerprint<goal_v3_t>(rbuf->data, size)) {
    decoded = decode_goal<goal_v3_t>("goal_v3_t", rbuf);
  } else {
    decoded.malformed =
        "malformed goal_t (or goal_v2_t, goal_v3_t): its fingerprint is none of theirs";
  }
  if (!decoded.malformed.empty()) {
    reject(channel, channel + ": " + decoded.malformed);
    return;
  }
  const int64_t goal_id = decoded.goal_id;
  if (goal_id >= 0) {
    std::optional<LostGoals> lost;
    if (options_.answer_goal_id_gaps) lost = goal_ids_.next(goal_id);
    std::lock_guard lock(mutex_);
    ++counters_.goals_received;
    last_goal_id_ = goal_id;
    if (lost) {
      counters_.goals_dropped += lost->count();
      intake_.lost.push_back(*lost);
    }
  }
  GoalRequest request;
  const Check c = decoded.convert(*scene_.problem.model, identity_, request);
  if (!c.ok) {
    reject(channel, channel + ": " + c.reason);
    // The sender named a goal: answer it, so no goal ever goes unanswered.
    if (goal_id >= 0) answer_with_failure(plan_t::INVALID_GOAL, c.reason, goal_id);
    return;
  }
  Intake arrived;
  arrived.goal = std::move(request);
  intake_.absorb(std::move(arrived));
}

void PlannerNode::on_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  obstacle_list_t msg;
  const int size = static_cast<int>(rbuf->data_size);
  if (lcmtypes::has_fingerprint<mesh_obstacle_list_t>(rbuf->data, size)) {
    on_mesh_obstacles(rbuf, channel);
    return;
  }
  if (auto s = lcmtypes::safe_decode(rbuf->data, size, msg); !s.ok) {
    // A version-1 sender (no source) is the unnamed source "".
    obstacle_list_v1_t v1;
    if (!lcmtypes::safe_decode(rbuf->data, size, v1).ok) {
      reject(channel, channel + ": malformed obstacle_list_t: " + s.reason);
      return;
    }
    msg = messages::obstacle_list_from_v1(v1);
  }
  if (std::string overlong = overlong_name(msg); !overlong.empty()) {
    reject(channel, channel + ": " + overlong);
    return;
  }
  Intake arrived;
  if (Check c = messages::obstacles_from_message(msg, arrived.obstacles); !c.ok) {
    reject(channel, channel + ": " + c.reason);
    return;
  }
  if (msg.replace_all) arrived.replaced_sources.insert(msg.source);
  arrived.obstacles_utime = msg.utime;
  intake_.absorb(std::move(arrived));
}

void PlannerNode::on_mesh_obstacles(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  mesh_obstacle_list_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed mesh_obstacle_list_t: " + s.reason);
    return;
  }
  if (std::string overlong = overlong_name(msg); !overlong.empty()) {
    reject(channel, channel + ": " + overlong);
    return;
  }
  Intake arrived;
  const std::string anchor = std::filesystem::path(scene_.source).parent_path().string();
  if (Check c = messages::mesh_obstacles_from_message(msg, anchor, arrived.obstacles); !c.ok) {
    reject(channel, channel + ": " + c.reason);
    return;
  }
  arrived.obstacles_utime = msg.utime;
  intake_.absorb(std::move(arrived));
}

void PlannerNode::on_payload(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  payload_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed payload_t: " + s.reason);
    return;
  }
  if (std::string overlong = overlong_name(msg); !overlong.empty()) {
    reject(channel, channel + ": " + overlong);
    return;
  }
  messages::PayloadChange change;
  if (Check c = messages::payload_from_message(msg, *scene_.problem.model, identity_, change);
      !c.ok) {
    reject(channel, channel + ": " + c.reason);
    return;
  }
  RobotWithPayload robot;
  try {
    robot = robot_with_payload(scene_, change.payload);
  } catch (const planning::SceneError& e) {
    reject(channel, channel + ": payload_t cannot be attached: " + e.what());
    return;
  }
  spdlog::info("{}: {}", channel,
               change.payload ? "payload of " + std::to_string(change.payload->mass) +
                                    " kg attached to '" + change.payload->frame + "'"
                              : std::string("payload detached"));
  std::lock_guard lock(mutex_);
  // Taken by the worker with the goals handed over after it, so they are planned with it.
  pending_robot_ = std::move(robot);
  ++counters_.payload_changes;
}

void PlannerNode::take_robot(RobotWithPayload robot) {
  robot_ = std::move(robot);
  // The incremental planner's graph is of the old robot.
  replanner_.reset();
}

void PlannerNode::on_state(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  robot_state_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed robot_state_t: " + s.reason);
    return;
  }
  if (std::string overlong = overlong_name(msg); !overlong.empty()) {
    reject(channel, channel + ": " + overlong);
    return;
  }
  // A state of this robot with NaN or Inf in it is a sensor fault: goals get INVALID_STATE.
  if (identity_.matches(msg.robot)) {
    if (std::string bad = non_finite_joint(msg); !bad.empty()) {
      refuse_state(channel, msg.utime, bad);
      return;
    }
  }
  MeasuredState state;
  if (Check c = messages::state_from_message(msg, *scene_.problem.model, identity_, state); !c.ok) {
    reject(channel, channel + ": " + c.reason);
    return;
  }
  take_state(channel, std::move(state));
}

void PlannerNode::on_iiwa_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  drake::lcmt_iiwa_status msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed lcmt_iiwa_status: " + s.reason);
    return;
  }
  // Drake's status names no robot: a NaN or Inf in it is a malformed message, dropped as if
  // lost, and the state age bound (--max-state-age) answers goals when no usable one follows.
  if (std::string bad = messages::non_finite_iiwa_field(msg, *scene_.problem.model); !bad.empty()) {
    reject(channel, channel + ": malformed " + bad);
    return;
  }
  MeasuredState state;
  if (Check c = messages::state_from_iiwa_status(msg, *scene_.problem.model, state); !c.ok) {
    reject(channel, channel + ": " + c.reason);
    return;
  }
  take_state(channel, std::move(state));
}

void PlannerNode::on_command(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  joint_command_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed joint_command_t: " + s.reason);
    return;
  }
  if (!identity_.matches(msg.robot)) return;
  std::lock_guard lock(mutex_);
  motion_join_.commanded(msg.plan_id, msg.utime);
}

void PlannerNode::on_heartbeat(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  planner_status_t msg;
  if (auto s = lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg); !s.ok) {
    reject(channel, channel + ": malformed planner_status_t: " + s.reason);
    return;
  }
  const std::size_t hash = std::hash<std::string_view>{}(
      std::string_view(static_cast<const char*>(rbuf->data), rbuf->data_size));
  std::string report;
  {
    std::lock_guard lock(mutex_);
    if (own_heartbeats_.judge(msg.utime, hash) != OwnHeartbeats::Verdict::kForeign) return;
    ++counters_.foreign_heartbeats;
    foreign_daemon_ = "another planner daemon publishes on " + channel + " (robot \"" +
                      truncated(msg.robot) + "\", its last plan id " +
                      std::to_string(msg.last_plan_id) +
                      "): both answer every goal, with colliding plan ids";
    const int64_t now = wall_utime();
    // Reported at once, then once a minute while it lasts.
    if (foreign_logged_utime_ == 0 || now - foreign_logged_utime_ >= 60'000'000) {
      foreign_logged_utime_ = now;
      report = foreign_daemon_ + " (" + std::to_string(counters_.foreign_heartbeats) +
               " of its heartbeats seen)";
    }
  }
  if (!report.empty()) spdlog::warn("{}", report);
}

void PlannerNode::take_state(const std::string& channel, MeasuredState&& state) {
  if (std::string beyond = state_beyond_limits(state, *scene_.problem.model); !beyond.empty()) {
    refuse_state(channel, state.utime, beyond);
    return;
  }
  Intake arrived;
  arrived.state = std::move(state);
  arrived.states = 1;
  intake_.absorb(std::move(arrived));
}

void PlannerNode::refuse_state(const std::string& channel, int64_t utime, std::string reason) {
  {
    std::lock_guard lock(mutex_);
    ++counters_.states_refused;
  }
  reject(channel, channel + ": measured state at utime " + std::to_string(utime) +
                      " cannot be a start: " + reason);
  Intake arrived;
  arrived.state_refused = std::move(reason);
  intake_.absorb(std::move(arrived));
}

void PlannerNode::hand_over() {
  if (intake_.empty()) return;
  {
    std::lock_guard lock(mutex_);
    if (intake_.state) {
      latest_state_ = std::move(intake_.state);
      state_refusal_.clear();
    }
    if (!intake_.state_refused.empty()) state_refusal_ = std::move(intake_.state_refused);
    state_count_ += intake_.states;
    intake_.state.reset();
    intake_.states = 0;
    intake_.state_refused.clear();
    pending_.absorb(std::move(intake_));
  }
  intake_ = Intake{};
  wake_.notify_one();
}

void PlannerNode::store_obstacles() {
  if (options_.state_file.empty()) return;
  std::map<ObstacleKey, ObstacleUpdate> copy;
  for (const auto& [key, o] : live_obstacles_) {
    ObstacleUpdate& u = copy[key];
    u.source = key.first;
    u.id = key.second;
    u.shape = o.shape;
    u.pose = o.pose;
  }
  std::lock_guard lock(mutex_);
  stored_obstacles_ = std::move(copy);
  stored_obstacles_dirty_ = true;
}

void PlannerNode::save_state_if_due() {
  std::lock_guard lock(mutex_);
  if (!stored_obstacles_dirty_) return;
  if (std::chrono::steady_clock::now() - state_written_at_ <
      std::chrono::duration<double>(kStateWritePeriod)) {
    return;
  }
  save_state_locked();
}

bool PlannerNode::apply_obstacles(const std::vector<ObstacleUpdate>& updates,
                                  const std::set<std::string>& replaced_sources) {
  bool changed = false;
  // A replace_all is one source's whole world: its obstacles the changes do not name go; the
  // ones named keep their ids, so that the planner sees a move rather than a removal and an
  // addition. Other sources' obstacles stay.
  for (auto it = live_obstacles_.begin(); it != live_obstacles_.end();) {
    const auto& [source, id] = it->first;
    const bool named = std::any_of(updates.begin(), updates.end(), [&](const ObstacleUpdate& u) {
      return !u.remove && u.source == source && u.id == id;
    });
    if (replaced_sources.count(source) != 0 && !named) {
      it = live_obstacles_.erase(it);
      changed = true;
    } else {
      ++it;
    }
  }
  // The world's bound (scene obstacles included) is checked before anything is added.
  const std::size_t fixed = scene_.problem.obstacles.size();
  std::vector<std::string> refused;
  for (const auto& u : updates) {
    const ObstacleKey key{u.source, u.id};
    auto it = live_obstacles_.find(key);
    if (!u.remove && it == live_obstacles_.end() &&
        fixed + live_obstacles_.size() >= static_cast<std::size_t>(collision::kMaxObstacles)) {
      refused.push_back(obstacle_name(key));
      continue;
    }
    if (u.remove) {
      if (it != live_obstacles_.end()) {
        live_obstacles_.erase(it);
        changed = true;
      } else {
        spdlog::info("obstacle {} to remove is not known; ignored", obstacle_name(key));
      }
      continue;
    }
    collision::Obstacle o;
    o.id = it != live_obstacles_.end() ? it->second.id : next_obstacle_id_++;
    o.shape = u.shape;
    o.pose = u.pose;
    live_obstacles_[key] = std::move(o);
    changed = true;
  }
  if (!refused.empty()) {
    reject(channel("OBSTACLES"),
           "obstacle " + refused.front() +
               (refused.size() > 1 ? " and " + std::to_string(refused.size() - 1) + " more" : "") +
               " not added: the world holds the most obstacles it may, " +
               std::to_string(collision::kMaxObstacles) + " (scene and LCM together)");
  }
  return changed;
}

void PlannerNode::plan_and_publish(const GoalRequest& goal, bool replan, int64_t trigger_utime) {
  planning::Problem problem = scene_.problem;
  if (robot_) {  // a payload_t changed the robot
    problem.model = robot_->model;
    problem.self_and_floor = robot_->self_and_floor;
  }
  bool new_state = false;
  std::optional<int64_t> state_utime;  // of the measured state the plan starts from
  std::optional<JoinPoint> join;       // where it joins the motion under way, if it does
  std::string stale;
  {
    std::lock_guard lock(mutex_);
    if (!state_refusal_.empty()) {
      stale = "the robot's latest measured state cannot be a start, " + state_refusal_;
    } else if (latest_state_) {
      const std::string what = replan
                                   ? "the obstacle update for goal " + std::to_string(goal.goal_id)
                                   : "goal " + std::to_string(goal.goal_id);
      stale = stale_state_reason(what, trigger_utime, *latest_state_);
    }
    if (stale.empty()) {
      state_ = planner_status_t::PLANNING;
      planning_goal_utime_ = goal.utime;
      // A measured state, when there is one, is where the robot is: plan from it.
      if (latest_state_) {
        problem.start_q = latest_state_->q;
        problem.start_qd = latest_state_->qd;
        state_utime = latest_state_->utime;
        // While an executor follows our plans, start where the commanded motion will be.
        join = motion_join_.join(latest_state_->utime, options_.max_state_age_s);
        if (join) {
          problem.start_q = join->q;
          problem.start_qd = join->qd;
        }
      }
      new_state = state_count_ != used_state_count_;
      used_state_count_ = state_count_;
    }
  }
  if (!stale.empty()) {
    spdlog::warn("goal {}: not planned: {}", goal.goal_id, stale);
    answer_with_failure(plan_t::INVALID_STATE, stale, goal.goal_id, /*first_answer=*/!replan);
    {
      std::lock_guard lock(mutex_);
      state_ = planner_status_t::IDLE;  // it may have yielded to neighbours as PLANNING
      last_message_ = stale;
    }
    publish_status();
    return;
  }
  spdlog::debug("goal {}: planning{}", goal.goal_id, replan ? " (replan)" : "");
  for (const auto& [name, obstacle] : live_obstacles_) problem.obstacles.push_back(obstacle);
  // Neighbours' bodies on this plan's clock: knot 0 is the state, the take-over, or now.
  std::optional<fleet::Decision> around;
  std::optional<int64_t> origin;  // without a state, the plan then starts when planning began
  if (neighbours_) {
    around = neighbours_->decide({goal.utime, ""}, !replan);
    origin = join ? join->takeover_utime : state_utime.value_or(wall_utime());
  }
  // Without states, a robot with neighbours moves along its plans on the common clock: a later
  // plan starts where they have it then, not back at the scene's start.
  const bool on_own_plans = neighbours_ && !state_utime && planned_motion_.moving();
  // A replan from the own plans starts at their next knot: the Bayes tree then goes on from the
  // same knots, renamed (Replanner::plan's warm_knots), rather than being warm-started anew.
  int shift_knots = 0;
  if (on_own_plans && replan) {
    if (const auto knot = planned_motion_.knot_from(*origin); knot && knot->index > 0) {
      origin = knot->utime;
      shift_knots = knot->index;
    }
  }
  const auto start_on_own_plans = [&](double wait_s) {
    const execution::Setpoint s = *planned_motion_.at(*origin + std::llround(wait_s * 1e6));
    problem.start_q = s.q;
    problem.start_qd = s.qd;
  };
  if (on_own_plans) start_on_own_plans(0.0);
  // Joints a goal does not name stay where this plan starts.
  problem.goal = messages::goal_for_start(goal, problem.start_q);
  problem.task_constraints.insert(problem.task_constraints.end(), goal.task_constraints.begin(),
                                  goal.task_constraints.end());
  if (goal.duration_s > 0) problem.horizon = goal.duration_s;
  const std::size_t own_obstacles = problem.obstacles.size();
  blocked_.reset();
  // A plan from a measured state says where the robot is from then on, one from the own plans in
  // force from its (possibly waited-for) start on, before which those plans move the robot; the
  // first plan from no state says it has stood at its start all along, so neighbours' motion
  // before knot 0 is checked too.
  const auto checked_from = [&](double wait_s) {
    return state_utime ? 0.0 : on_own_plans ? wait_s : -std::numeric_limits<double>::infinity();
  };

  planning::Plan plan;
  bool threw = false;
  std::string error;
  double wait_s = 0;       // the start held for a followed neighbour's plan to end
  std::string waited_for;  // that neighbour
  std::string refusal;     // the coordination rule's failure reason for a plan that ran into one
  std::optional<fleet::Blocker> refused_by;  // the neighbour that plan ran into
  // Each wait goes to a later plan end, so there are at most as many as neighbours.
  for (std::size_t attempt = 0;; ++attempt) {
    if (neighbours_) {
      // After a wait the robot has gone on along its plans until the later start.
      if (on_own_plans && attempt > 0) start_on_own_plans(wait_s);
      problem.obstacles.resize(own_obstacles);
      neighbours_->add_obstacles(*around, *origin + std::llround(wait_s * 1e6), problem.obstacles);
    }
    // A replan from the own plans in force starts from them continued in time: re-anchoring the
    // current plan at a start further along it would have to drag its whole trajectory there.
    std::optional<planning::Plan> continued;
    if (on_own_plans && replan) {
      continued = planned_motion_.ahead(*origin + std::llround(wait_s * 1e6), problem.horizon,
                                        problem.steps);
    }
    try {
      // Only the solve is cancelled: the collision walks outside it (neighbours, shutdown's
      // obstacle changes) must run to their end.
      graph::CancellationScope cancellation(cancel_);
      plan = replanner_.plan(problem, /*new_goal=*/!replan && attempt == 0,
                             continued ? &*continued : nullptr, attempt == 0 ? shift_knots : 0);
    } catch (const graph::Cancelled&) {
      spdlog::info("goal {}: planning cancelled: {}", goal.goal_id, kShutdownReason);
      answer_with_failure(plan_t::CANCELLED, std::string("planning cancelled: ") + kShutdownReason,
                          goal.goal_id, /*first_answer=*/!replan);
      {
        std::lock_guard lock(mutex_);
        state_ = planner_status_t::IDLE;
        last_message_ = kShutdownReason;
      }
      return;
    } catch (const std::exception& e) {
      threw = true;
      error = e.what();
    }
    if (threw || !neighbours_) break;
    // A valid plan must also stay clear of the neighbours it follows while they still move after
    // it ends (the planner sees only its own span); a failed one that comes within the margin of
    // a neighbour ran into it. A problem refused before solving (a goal in collision) has no
    // trajectory: its goal, held from the start, is what ran into the neighbour.
    const bool refused = plan.q.rows() < 2 && problem.goal.kind == planning::Goal::Kind::kJoint;
    std::string why;
    const double contact = plan.success() ? 0.0 : problem.objectives.collision_epsilon;
    std::optional<fleet::Blocker> blocker = neighbours_->blocker(
        *around, *origin, *problem.model,
        refused ? fleet::standing_plan(problem.goal.q, problem.horizon) : plan, wait_s, contact,
        checked_from(wait_s), why);
    bool goal_blocked = refused;
    // A failed plan ends wherever its solve stopped, so keeping clear says little; its goal,
    // held from the horizon on, is where any plan must stand while a neighbour may still pass.
    if (!blocker && !refused && !plan.success() &&
        problem.goal.kind == planning::Goal::Kind::kJoint) {
      blocker = neighbours_->blocker(
          *around, *origin, *problem.model, fleet::standing_plan(problem.goal.q, problem.horizon),
          wait_s, contact, std::max(checked_from(wait_s), wait_s + problem.horizon), why);
      goal_blocked = blocker.has_value();
    }
    if (goal_blocked) {
      why = "its goal: " + why;
    } else if (!plan.success() && !plan.stats.reason.empty()) {
      why += " (" + neighbours_->name_bodies(plan.stats.reason) + ")";
    }
    if (!blocker) break;
    // A robot joining a motion under way does not wait: the executor would go on meanwhile.
    const std::string no_wait = !options_.wait_for_neighbours   ? "waiting is off"
                                : join                          ? "it joins a motion under way"
                                : attempt > neighbours_->size() ? "it waited for every neighbour"
                                                                : "";
    const fleet::Remedy r =
        fleet::remedy(identity_.channel_prefix, *blocker, wait_s, problem.horizon, no_wait, why);
    if (r.kind == fleet::Remedy::Kind::kWait) {
      spdlog::info("goal {}: {} ({})", goal.goal_id, r.reason, why);
      wait_s = r.wait.wait;
      waited_for = blocker->name;
      continue;
    }
    refusal = r.reason;
    refused_by = blocker;
    if (r.kind == fleet::Remedy::Kind::kFail &&
        blocker->treatment == fleet::Treatment::kHeldAtState) {
      blocked_ = BlockedAnswer{goal.goal_id, blocker->name, blocker->prefix, why};
    }
    break;
  }
  const bool valid = !threw && plan.success() && refusal.empty();
  const planning::ReplanReport& report = replanner_.last_report();
  // A state the incremental planner refused (or never saw, after an exception) is offered again.
  if (!valid) {
    std::lock_guard lock(mutex_);
    if (new_state) --used_state_count_;
  }
  const std::string wait_note = valid && wait_s > 0 ? fleet::wait_note(waited_for, wait_s) : "";

  int64_t plan_id;
  messages::PlanTime time;
  {
    std::lock_guard lock(mutex_);
    time = clock_now_locked();
    plan_id = take_plan_id_locked();
    last_plan_id_ = plan_id;
    ++counters_.plans_published;
    if (!replan) ++counters_.goals_answered;
    if (replan) ++counters_.replans;
    if (!threw && report.incremental) ++counters_.incremental;
    if (!threw && report.fell_back) ++counters_.fallbacks;
    if (!valid) ++counters_.failures;
    if (valid && wait_s > 0) ++counters_.neighbour_waits;
    state_ = threw ? planner_status_t::ERROR : planner_status_t::IDLE;
    last_message_ = threw              ? error
                    : !refusal.empty() ? refusal
                    : plan.success()   ? wait_note
                                       : plan.stats.reason;
    if (neighbours_) last_message_ = neighbours_->name_bodies(last_message_);
    if (valid) {
      valid_plan_id_ = plan_id;
      valid_goal_utime_ = goal.utime;
    }
  }
  // Failed attempts count too: a higher neighbour's change after a refusal is one to replan for.
  if (around) neighbours_->planned(*around, valid, valid || !refused_by ? nullptr : &*refused_by);
  // Knot 0 is the measured state, at its own time, or where the motion under way will be at
  // the take-over; without a state the plan starts when it is published (with neighbours, when
  // planning began: the time their bodies were placed on); after a wait, that much later, the
  // robot holding its start until then.
  time.state_utime = state_utime.value_or(-1);
  time.start_utime =
      (join ? join->takeover_utime : state_utime.value_or(origin.value_or(time.utime))) +
      std::llround(wait_s * 1e6);
  time.takeover_utime = time.start_utime;
  plan_t msg;
  if (threw) {
    spdlog::error("goal {}: planner error: {}", goal.goal_id, error);
    msg = messages::failure_message(plan_t::FAILED, "planner error: " + error, identity_.model_name,
                                    plan_id, goal.goal_id, time);
  } else if (!refusal.empty()) {
    spdlog::warn("goal {}: plan {} refused: {}", goal.goal_id, plan_id, refusal);
    msg = messages::failure_message(plan_t::FAILED, refusal, identity_.model_name, plan_id,
                                    goal.goal_id, time);
  } else {
    msg = messages::plan_to_message(plan, *problem.model, identity_.model_name, plan_id,
                                    goal.goal_id, time);
    msg.method = report.method;
    if (neighbours_) msg.status_message = neighbours_->name_bodies(msg.status_message);
    if (!wait_note.empty()) msg.status_message = wait_note;
    spdlog::info("goal {}: plan {} {} ({}, {} iterations, {:.1f} ms){}", goal.goal_id, plan_id,
                 plan.success() ? "valid" : "INVALID", msg.method, plan.stats.iterations,
                 plan.stats.solve_time_s * 1e3, wait_note.empty() ? "" : "; " + wait_note);
  }
  // Recorded before it is sent, so that the executor's first command of it is recognised.
  if (msg.status == plan_t::SUCCESS) {
    std::lock_guard lock(mutex_);
    if (join) {
      ++counters_.joined;
      // Planning took longer than expected: the executor switches late, with a jump.
      if (latest_state_ && latest_state_->utime > join->takeover_utime) {
        ++counters_.late_takeovers;
        spdlog::warn(
            "goal {}: plan {} published {:.3f} s after its take-over (--takeover-latency "
            "{} s is too short for this planner)",
            goal.goal_id, plan_id,
            static_cast<double>(latest_state_->utime - join->takeover_utime) * 1e-6,
            options_.takeover_latency_s);
      }
    }
    motion_join_.published(
        {plan_id, time.start_utime, time.takeover_utime, time.state_utime, plan});
    planned_motion_.published(
        {plan_id, time.start_utime, time.takeover_utime, time.state_utime, plan});
  }
  publish(channel("PLAN"), msg);
  if (msg.status == plan_t::SUCCESS) current_plan_msg_ = msg;
  if (!options_.drake_plan_channel.empty() && msg.status == plan_t::SUCCESS) {
    drake::lcmt_robot_plan drake_plan = messages::robot_plan_from_plan(msg);
    publish(options_.drake_plan_channel, drake_plan);
  }
  publish_status();
  // Answered: while the node waits for the next change, the incremental planner readies its
  // tree, so that a replan re-eliminates only what its change touches.
  if (!valid) return;
  try {
    replanner_.prepare();
  } catch (const std::exception& e) {  // the next request is planned from scratch
    spdlog::warn("goal {}: preparing the next replan failed: {}", goal.goal_id, e.what());
    replanner_.reset();
  }
}

void PlannerNode::answer_at_shutdown(const Intake& taken) {
  answer_superseded(taken);
  // Obstacle changes are kept (for the state file), not planned.
  if ((!taken.obstacles.empty() || !taken.replaced_sources.empty()) &&
      apply_obstacles(taken.obstacles, taken.replaced_sources)) {
    store_obstacles();
  }
  if (!taken.goal) return;
  spdlog::info("goal {}: not planned: {}", taken.goal->goal_id, kShutdownReason);
  answer_with_failure(plan_t::CANCELLED, std::string("not planned: ") + kShutdownReason,
                      taken.goal->goal_id);
}

void PlannerNode::worker_loop(const std::atomic<bool>& stop) {
  while (true) {
    Intake taken;
    std::optional<RobotWithPayload> robot;
    bool stopping;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(50),
                     [&] { return stop.load() || !pending_.empty(); });
      stopping = stop.load();
      std::swap(taken, pending_);
      std::swap(robot, pending_robot_);
    }
    if (robot) take_robot(*std::move(robot));
    if (stopping) {
      answer_at_shutdown(taken);
      return;
    }
    save_state_if_due();
    answer_superseded(taken);
    const bool obstacles_changed = (!taken.obstacles.empty() || !taken.replaced_sources.empty()) &&
                                   apply_obstacles(taken.obstacles, taken.replaced_sources);
    if (obstacles_changed) store_obstacles();
    if (taken.goal) {
      current_goal_ = taken.goal;
      yield_to_neighbours(*taken.goal);
      plan_and_publish(*taken.goal, /*replan=*/false, taken.goal->utime);
    } else if (obstacles_changed && current_goal_) {
      yield_to_neighbours(*current_goal_);
      plan_and_publish(*current_goal_, /*replan=*/true, taken.obstacles_utime);
    } else if (neighbours_ && current_goal_ && neighbours_->take_changed()) {
      replan_for_neighbours();
    }
    if (neighbours_ && neighbours_->take_joined()) republish_current_plan();
  }
}

void PlannerNode::republish_current_plan() {
  if (current_plan_msg_) publish(channel("PLAN_CURRENT"), *current_plan_msg_);
}

void PlannerNode::replan_for_neighbours() {
  const fleet::Decision d = neighbours_->decide({current_goal_->utime, ""}, false);
  if (!d.replan) {
    answer_deadlock();
    return;
  }
  int64_t trigger_utime = current_goal_->utime;
  {
    std::lock_guard lock(mutex_);
    ++counters_.neighbour_replans;
    if (latest_state_) trigger_utime = latest_state_->utime;  // a neighbour's change is now
  }
  spdlog::info("goal {}: replanning: {}", current_goal_->goal_id, d.reason);
  yield_to_neighbours(*current_goal_);
  plan_and_publish(*current_goal_, /*replan=*/true, trigger_utime);
}

void PlannerNode::yield_to_neighbours(const GoalRequest& goal) {
  if (!neighbours_ || options_.neighbour_yield_s <= 0) return;
  {
    std::lock_guard lock(mutex_);
    state_ = planner_status_t::PLANNING;
    planning_goal_utime_ = goal.utime;
  }
  publish_status();
  const auto start = std::chrono::steady_clock::now();
  const auto pause = [&](int ms) {
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, std::chrono::milliseconds(ms), [&] { return cancel_.load(); });
  };
  // A neighbour that got its goal at the same moment announces its plan a network trip later.
  pause(kYieldListen);
  bool yielded = false;
  while (!cancel_) {
    const std::string above = neighbours_->planning_above(goal.utime);
    if (above.empty()) break;
    const double waited = graph::seconds_since(start);
    if (!yielded) {
      spdlog::info("goal {}: yields to neighbour '{}', which is making a plan of higher priority",
                   goal.goal_id, above);
    }
    yielded = true;
    if (waited >= options_.neighbour_yield_s) {
      spdlog::warn("goal {}: planning after yielding {:.3f} s, the most allowed: neighbour '{}' "
                   "is still making its plan",
                   goal.goal_id, waited, above);
      break;
    }
    pause(10);
  }
  if (!yielded) return;
  spdlog::info("goal {}: planning after yielding {:.3f} s to neighbours' plans in the making",
               goal.goal_id, graph::seconds_since(start));
  std::lock_guard lock(mutex_);
  ++counters_.neighbour_yields;
}

void PlannerNode::answer_deadlock() {
  if (!blocked_ || !current_goal_ || blocked_->goal_id != current_goal_->goal_id) return;
  const std::vector<std::string> cycle = neighbours_->blocking_cycle(blocked_->name);
  if (cycle.empty()) return;
  const std::string reason = fleet::deadlock_reason(identity_.channel_prefix, blocked_->name,
                                                    blocked_->prefix, blocked_->why, cycle);
  spdlog::warn("goal {}: {}", blocked_->goal_id, reason);
  {
    std::lock_guard lock(mutex_);
    last_message_ = reason;
  }
  answer_with_failure(plan_t::FAILED, reason, blocked_->goal_id, /*first_answer=*/false);
  blocked_.reset();
  publish_status();
}

void PlannerNode::publish_status() {
  planner_status_t msg;
  std::vector<uint8_t> bytes;
  {
    std::lock_guard lock(mutex_);
    msg.utime = own_heartbeats_.next_utime(wall_utime());
    msg.robot = identity_.model_name;
    msg.state = state_;
    msg.last_goal_id = last_goal_id_;
    msg.last_plan_id = last_plan_id_;
    msg.message = last_message_;
    // planner_status_t has no fields for failed publishes or a second daemon: the text says.
    const auto append = [&](const std::string& text) {
      msg.message += (msg.message.empty() ? "" : "; ") + text;
    };
    if (counters_.publish_failures > 0) {
      append(std::to_string(counters_.publish_failures) +
             " publishes failed since start, the last on " + last_publish_failure_);
    }
    if (!foreign_daemon_.empty()) append(foreign_daemon_);
    msg.num_plans = counters_.plans_published;
    msg.num_failures = counters_.failures;
    msg.num_goals_received = counters_.goals_received;
    msg.num_goals_answered = counters_.goals_answered;
    msg.num_goals_superseded = counters_.goals_superseded;
    msg.num_goals_dropped = counters_.goals_dropped;
    msg.model_id = model_id_;
    const Eigen::Vector3d base = scene_.base.translation();
    const Eigen::Quaterniond turn(scene_.base.linear());
    for (int i = 0; i < 3; ++i) msg.base_position[i] = base[i];
    msg.base_quaternion[0] = turn.w();
    msg.base_quaternion[1] = turn.x();
    msg.base_quaternion[2] = turn.y();
    msg.base_quaternion[3] = turn.z();
    msg.goal_utime = valid_goal_utime_;
    msg.valid_plan_id = valid_plan_id_;
    msg.num_neighbour_replans = static_cast<int32_t>(counters_.neighbour_replans);
    msg.planning_goal_utime = state_ == planner_status_t::PLANNING ? planning_goal_utime_ : -1;
    if (neighbours_) msg.neighbours = neighbours_->summary();
    // Recorded before it is sent, under the lock that gave it its utime, so that its
    // loop-back is always recognised as ours.
    bytes.resize(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    own_heartbeats_.record(msg.utime,
                           std::hash<std::string_view>{}(std::string_view(
                               reinterpret_cast<const char*>(bytes.data()), bytes.size())));
  }
  publish_bytes(planner_status_t::getTypeName(), channel("PLANNER_STATUS"), bytes.data(),
                static_cast<unsigned>(bytes.size()));
}

void PlannerNode::publish_shutdown_mark() {
  shutdown_mark_ = std::to_string(reinterpret_cast<std::uintptr_t>(this)) + "@" +
                   std::to_string(getpid());
  shutdown_mark_seen_ = false;
  shutdown_mark_subscription_ =
      lcm_->subscribe(channel("SHUTDOWN_MARK"), &PlannerNode::on_shutdown_mark, this);
  publish_bytes("shutdown marker", channel("SHUTDOWN_MARK"), shutdown_mark_.data(),
                static_cast<unsigned>(shutdown_mark_.size()));
}

void PlannerNode::on_shutdown_mark(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  shutdown_mark_seen_ =
      shutdown_mark_seen_ ||
      std::string_view(static_cast<const char*>(rbuf->data), rbuf->data_size) == shutdown_mark_;
}

void PlannerNode::drain_until_mark() {
  // LCM's receive thread may not yet have queued what is in the socket; the marker, sent after
  // the stop, comes after all of it.
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(kShutdownMarkWait);
  for (int handled = 0; !shutdown_mark_seen_ && handled < kGoalQueueCapacity;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          end - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      spdlog::warn("kinographd: own shutdown marker not back within {} ms", kShutdownMarkWait);
      break;
    }
    const int n = lcm_->handleTimeout(static_cast<int>(left));
    if (n < 0) break;
    handled += n;
  }
  lcm_->unsubscribe(shutdown_mark_subscription_);
  shutdown_mark_subscription_ = nullptr;
}

void PlannerNode::run(const std::atomic<bool>& stop, int wake_fd) {
  spdlog::info("kinographd: robot {} on channels {}_*", identity_.model_name,
               identity_.channel_prefix);
  if (!options_.iiwa_status_channel.empty()) {
    spdlog::info("kinographd: Drake's lcmt_iiwa_status on {} is the robot's state too",
                 options_.iiwa_status_channel);
  }
  if (!options_.drake_plan_channel.empty()) {
    spdlog::info("kinographd: valid plans also as Drake's lcmt_robot_plan on {}",
                 options_.drake_plan_channel);
  }
  // The worker stops on `done`, not on `stop`, so that an LCM failure also ends it.
  cancel_ = false;
  std::atomic<bool> done{false};
  // Process signals (SIGTERM) reach the thread that runs run(), never the worker (LCM blocks
  // them in its own thread): a stop is then seen before more of what LCM holds is planned.
  sigset_t all_signals, previous_mask;
  sigfillset(&all_signals);
  pthread_sigmask(SIG_BLOCK, &all_signals, &previous_mask);
  std::thread worker([&] { worker_loop(done); });
  pthread_sigmask(SIG_SETMASK, &previous_mask, nullptr);
  auto next_status = std::chrono::steady_clock::now();
  int handle_failures = 0;
  while (!stop.load()) {
    if (std::chrono::steady_clock::now() >= next_status) {
      publish_status();
      flush_reject_log();
      next_status += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(options_.status_period_s));
    }
    // LCM traffic or a stop request, whichever comes first (a signal's EINTR is one too).
    if (!wait_readable(lcm_->getFileno(), wake_fd, 50)) {
      if (stop.load()) break;
      hand_over();
      continue;
    }
    // LCM 1.3's udpm handle() occasionally reports a failure for a single datagram (seen when
    // a packet of our own arrives while no handler wants it); only a persistent failure means
    // the transport is gone.
    const int handled = lcm_->handleTimeout(0);
    if (handled < 0) {
      if (++handle_failures > 100) {
        spdlog::error("LCM handle failed 100 times in a row; stopping");
        break;
      }
      spdlog::debug("LCM handle failed once; continuing");
      wait_readable(-1, wake_fd, 5);  // not a busy loop on a broken transport; a stop ends it
    } else {
      handle_failures = 0;
      // A burst (messages less than 1 ms apart, as after a stall) is taken whole before the
      // worker sees any of it, so that only its newest goal is planned; at most 5 ms, so that a
      // steady storm still reaches the worker.
      const auto drain_end = std::chrono::steady_clock::now() + std::chrono::milliseconds(5);
      while (handled > 0 && !stop.load() && std::chrono::steady_clock::now() < drain_end &&
             lcm_->handleTimeout(1) > 0) {
      }
    }
    // Once stopping, nothing more is handed to the worker to plan: it is answered below.
    if (stop.load()) break;
    hand_over();
  }
  // A solve under way ends at its next iteration; the worker answers what it holds and ends.
  cancel_ = true;
  done = true;
  wake_.notify_all();
  publish_shutdown_mark();  // comes back while the worker ends
  worker.join();
  // What reached LCM before the stop is still taken and answered here (bounded: a storm cannot
  // hold the exit up), so that no goal that arrived goes unanswered.
  drain_until_mark();
  hand_over();
  Intake left;
  {
    std::lock_guard lock(mutex_);
    std::swap(left, pending_);
  }
  answer_at_shutdown(left);
  {
    std::lock_guard lock(mutex_);
    // The ids used are all below next_plan_id_: the next daemon starts there, not at the
    // reservation's end.
    plan_ids_reserved_ = next_plan_id_;
    save_state_locked();
  }
  publish_status();
}

}  // namespace kinograph::daemon
