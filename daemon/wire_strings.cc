#include "daemon/wire_strings.h"

namespace kinograph::daemon {
namespace {

std::string check(const std::string& field, const std::string& value,
                  std::size_t max = kMaxWireName) {
  if (value.size() <= max) return {};
  return field + " is " + std::to_string(value.size()) + " bytes long, more than the " +
         std::to_string(max) + " allowed: \"" + truncated(value) + "\"";
}

}  // namespace

std::string truncated(const std::string& s, std::size_t max) {
  if (s.size() <= max) return s;
  std::size_t end = max;
  // Never cut inside a UTF-8 sequence: back up over continuation bytes (10xxxxxx).
  while (end > 0 && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) --end;
  return s.substr(0, end) + "…";
}

std::string overlong_name(const goal_t& msg) {
  if (std::string r = check("goal_t.robot", msg.robot); !r.empty()) return r;
  return check("goal_t.ee_frame", msg.ee_frame);
}

namespace {

// Goals of version 2 and later name the same strings; `type` names the message.
template <class GoalMessage>
std::string overlong_named_goal(const std::string& type, const GoalMessage& msg) {
  if (std::string r = check(type + ".robot", msg.robot); !r.empty()) return r;
  if (std::string r = check(type + ".ee_frame", msg.ee_frame); !r.empty()) return r;
  for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
    std::string r = check(type + ".joint_name[" + std::to_string(i) + "]", msg.joint_name[i]);
    if (!r.empty()) return r;
  }
  for (std::size_t i = 0; i < msg.task_constraint.size(); ++i) {
    std::string r = check(type + ".task_constraint[" + std::to_string(i) + "].frame",
                          msg.task_constraint[i].frame);
    if (!r.empty()) return r;
  }
  return {};
}

}  // namespace

std::string overlong_name(const goal_v2_t& msg) { return overlong_named_goal("goal_v2_t", msg); }

std::string overlong_name(const goal_v3_t& msg) { return overlong_named_goal("goal_v3_t", msg); }

std::string overlong_name(const payload_t& msg) {
  if (std::string r = check("payload_t.robot", msg.robot); !r.empty()) return r;
  return check("payload_t.frame", msg.frame);
}

std::string overlong_name(const mesh_obstacle_list_t& msg) {
  if (std::string r = check("mesh_obstacle_list_t.source", msg.source); !r.empty()) return r;
  for (std::size_t i = 0; i < msg.obstacles.size(); ++i) {
    const std::string field = "mesh_obstacle_list_t.obstacles[" + std::to_string(i) + "]";
    if (std::string r = check(field + ".id", msg.obstacles[i].id); !r.empty()) return r;
    if (std::string r = check(field + ".mesh", msg.obstacles[i].mesh, kMaxWirePath); !r.empty())
      return r;
  }
  return {};
}

std::string overlong_name(const robot_state_t& msg) {
  if (std::string r = check("robot_state_t.robot", msg.robot); !r.empty()) return r;
  for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
    std::string r = check("robot_state_t.joint_name[" + std::to_string(i) + "]", msg.joint_name[i]);
    if (!r.empty()) return r;
  }
  return {};
}

std::string overlong_name(const obstacle_list_t& msg) {
  if (std::string r = check("obstacle_list_t.source", msg.source); !r.empty()) return r;
  for (std::size_t i = 0; i < msg.obstacles.size(); ++i) {
    std::string r =
        check("obstacle_list_t.obstacles[" + std::to_string(i) + "].id", msg.obstacles[i].id);
    if (!r.empty()) return r;
  }
  return {};
}

}  // namespace kinograph::daemon
