#include "daemon/wire_strings.h"

namespace kinograph::daemon {
namespace {

std::string check(const std::string& field, const std::string& value) {
  if (value.size() <= kMaxWireName) return {};
  return field + " is " + std::to_string(value.size()) + " bytes long, more than the " +
         std::to_string(kMaxWireName) + " allowed: \"" + truncated(value) + "\"";
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

std::string overlong_name(const robot_state_t& msg) {
  if (std::string r = check("robot_state_t.robot", msg.robot); !r.empty()) return r;
  for (std::size_t i = 0; i < msg.joint_name.size(); ++i) {
    std::string r = check("robot_state_t.joint_name[" + std::to_string(i) + "]", msg.joint_name[i]);
    if (!r.empty()) return r;
  }
  return {};
}

std::string overlong_name(const obstacle_list_t& msg) {
  for (std::size_t i = 0; i < msg.obstacles.size(); ++i) {
    std::string r =
        check("obstacle_list_t.obstacles[" + std::to_string(i) + "].id", msg.obstacles[i].id);
    if (!r.empty()) return r;
  }
  return {};
}

}  // namespace kinograph::daemon
