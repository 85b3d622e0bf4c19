// Fuzz target: every kinograph and Drake LCM message as kinographd receives it. The bytes are
// tried as each type (the fingerprint picks at most one): safe_decode, then, for an accepted
// message, the daemon's checks and conversion against the iiwa14. Findings: a crash, a sanitizer
// report, an exception escaping a check, or an accepted message that does not re-encode to the
// same bytes (safe_decode must accept only what decode reads exactly).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fuzz/fuzz_data.h"
#include "kinograph/lcm/drake_convert.h"
#include "kinograph/lcm/message_convert.h"
#include "lcmtypes/safe_decode.h"

namespace {

using namespace kinograph;

// An accepted message must be exactly the bytes received: no slack safe_decode let through.
template <typename Msg>
void expect_round_trip(const Msg& msg, const uint8_t* data, size_t size, const char* type) {
  const int n = msg.getEncodedSize();
  std::vector<uint8_t> bytes(static_cast<size_t>(n));
  if (msg.encode(bytes.data(), 0, n) != n || bytes.size() != size ||
      !std::equal(bytes.begin(), bytes.end(), data)) {
    fuzz::fail(std::string(type) + " accepted by safe_decode does not re-encode to its bytes");
  }
}

// Decodes `data` as Msg; on success checks the round trip and hands the message to `convert`.
template <typename Msg, typename Convert>
void try_type(const uint8_t* data, size_t size, const char* type, Convert convert) {
  Msg msg;
  if (!lcmtypes::safe_decode(data, static_cast<int>(size), msg).ok) return;
  expect_round_trip(msg, data, size, type);
  convert(msg);
}

const messages::RobotIdentity kIdentity{"iiwa14", "IIWA"};

void convert_goal(const messages::GoalRequest& request, const messages::Check& check) {
  if (!check.ok) return;
  const Eigen::VectorXd start = Eigen::VectorXd::Zero(fuzz::iiwa_model().nq());
  (void)messages::goal_for_start(request, start);
}

void convert_obstacles(const obstacle_list_t& msg) {
  std::vector<messages::ObstacleUpdate> updates;
  const messages::Check check = messages::obstacles_from_message(msg, updates);
  if (check.ok && static_cast<int32_t>(updates.size()) != msg.num_obstacles) {
    fuzz::fail("obstacles_from_message accepted a list but converted a different count");
  }
}

void convert_plan(const plan_t& msg) {
  (void)messages::plan_from_message(msg);
  try {
    (void)messages::robot_plan_from_plan(msg);
  } catch (const std::invalid_argument&) {
    // A plan without trajectory or with more joints than Drake's int16: refused by design.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > static_cast<size_t>(INT32_MAX)) return 0;
  const dynamics::Model& model = fuzz::iiwa_model();
  try_type<goal_t>(data, size, "goal_t", [&](const goal_t& m) {
    messages::GoalRequest request;
    convert_goal(request, messages::goal_from_message(m, model, kIdentity, request));
  });
  try_type<goal_v2_t>(data, size, "goal_v2_t", [&](const goal_v2_t& m) {
    messages::GoalRequest request;
    convert_goal(request, messages::goal_from_message(m, model, kIdentity, request));
  });
  try_type<obstacle_list_t>(data, size, "obstacle_list_t", convert_obstacles);
  try_type<obstacle_list_v1_t>(data, size, "obstacle_list_v1_t", [](const obstacle_list_v1_t& m) {
    convert_obstacles(messages::obstacle_list_from_v1(m));
  });
  try_type<robot_state_t>(data, size, "robot_state_t", [&](const robot_state_t& m) {
    messages::MeasuredState state;
    (void)messages::state_from_message(m, model, kIdentity, state);
  });
  try_type<joint_command_t>(data, size, "joint_command_t", [&](const joint_command_t& m) {
    messages::CommandSetpoint setpoint;
    if (messages::command_from_message(m, model, kIdentity, setpoint).ok) {
      (void)messages::command_to_message(setpoint, model);
    }
  });
  try_type<plan_t>(data, size, "plan_t", convert_plan);
  try_type<plan_v1_t>(data, size, "plan_v1_t",
                      [](const plan_v1_t& m) { (void)messages::plan_from_message(m); });
  try_type<planner_status_t>(data, size, "planner_status_t", [](const planner_status_t&) {});
  try_type<stop_request_t>(data, size, "stop_request_t", [](const stop_request_t&) {});
  try_type<drake::lcmt_iiwa_status>(data, size, "lcmt_iiwa_status",
                                    [&](const drake::lcmt_iiwa_status& m) {
                                      messages::MeasuredState state;
                                      (void)messages::state_from_iiwa_status(m, model, state);
                                    });
  try_type<drake::lcmt_robot_plan>(data, size, "lcmt_robot_plan",
                                   [](const drake::lcmt_robot_plan&) {});
  return 0;
}
