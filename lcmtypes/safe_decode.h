#pragma once
// Defensive decoding of kinograph LCM messages that arrive from the network.
//
// The decode() that lcm-gen 1.3.1 writes trusts the counts inside the message: it resizes each
// array to its count *before* checking that the bytes are there, so a 30-byte message with
// num_joints = 2^31 - 1 asks for tens of gigabytes, a negative count or a zero string length
// throws std::length_error, and decoding into a reused object keeps stale array contents when
// a count is 0. safe_decode() first walks the wire format (mirroring the .lcm files, each
// version of a type its own struct) and checks every count and string length against the bytes
// that remain, then decodes into a fresh object and catches anything left.
#include <cstdint>
#include <cstring>
#include <exception>
#include <string>
#include <utility>

#include "drake/lcmt_iiwa_status.hpp"
#include "drake/lcmt_robot_plan.hpp"
#include "drake/lcmt_robot_state.hpp"
#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/joint_command_t.hpp"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/mesh_obstacle_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/obstacle_list_v1_t.hpp"
#include "kinograph/obstacle_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/plan_v1_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planner_status_v2_t.hpp"
#include "kinograph/planner_status_v3_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "kinograph/stop_request_t.hpp"
#include "kinograph/task_constraint_t.hpp"

namespace kinograph::lcmtypes {

/// Outcome of decoding one received message: ok, or why it was rejected (naming the field).
struct DecodeStatus {
  bool ok = false;
  std::string reason;
};

namespace detail {

/// Bounds-checked cursor over an LCM encoding (big-endian, strings as int32 length
/// including the NUL, then the bytes). The first failure is kept in error().
class WireReader {
 public:
  WireReader(const void* data, int64_t size)
      : data_(static_cast<const uint8_t*>(data)), size_(size < 0 ? 0 : size) {}

  int64_t remaining() const { return size_ - pos_; }
  bool at_end() const { return pos_ == size_; }
  const std::string& error() const { return error_; }

  /// Skips `count` fixed-size elements of `bytes` each.
  bool skip(int64_t count, int64_t bytes, const char* field) {
    if (count * bytes > remaining()) {
      return fail(std::string(field) + ": needs " + std::to_string(count * bytes) + " bytes, " +
                  std::to_string(remaining()) + " left");
    }
    pos_ += count * bytes;
    return true;
  }
  bool read_i32(int32_t& v, const char* field) {
    if (remaining() < 4) return fail(std::string(field) + ": truncated");
    uint32_t u = 0;
    for (int i = 0; i < 4; ++i) u = (u << 8) | data_[pos_ + i];
    pos_ += 4;
    v = static_cast<int32_t>(u);
    return true;
  }
  bool read_i16(int16_t& v, const char* field) {
    if (remaining() < 2) return fail(std::string(field) + ": truncated");
    v = static_cast<int16_t>((data_[pos_] << 8) | data_[pos_ + 1]);
    pos_ += 2;
    return true;
  }
  bool read_i64(int64_t& v, const char* field) {
    if (remaining() < 8) return fail(std::string(field) + ": truncated");
    uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u = (u << 8) | data_[pos_ + i];
    pos_ += 8;
    v = static_cast<int64_t>(u);
    return true;
  }
  /// A string: its length (with the NUL) must be at least 1 and fit in what remains, and its
  /// only NUL must be the last byte, as every LCM encoder writes it.
  bool string(const char* field) {
    int32_t len = 0;
    if (!read_i32(len, field)) return false;
    if (len < 1) return fail(std::string(field) + ": string length " + std::to_string(len));
    if (!skip(len, 1, field)) return false;
    if (data_[pos_ - 1] != 0) return fail(std::string(field) + ": string not NUL-terminated");
    // LCM strings are C strings: an inner NUL would not survive re-encoding.
    if (std::memchr(data_ + pos_ - len, 0, len - 1) != nullptr) {
      return fail(std::string(field) + ": NUL inside the string");
    }
    return true;
  }
  /// A boolean: one byte, 0 or 1 (any other value would be an invalid bool after decode).
  bool boolean(const char* field) {
    if (remaining() < 1) return fail(std::string(field) + ": truncated");
    if (data_[pos_] > 1) {
      return fail(std::string(field) + ": boolean byte " + std::to_string(data_[pos_]));
    }
    ++pos_;
    return true;
  }
  /// An array count: not negative, and each element needs at least `min_elem_bytes` bytes,
  /// which bounds the count by what remains before anything is allocated.
  bool count(int32_t& n, int64_t min_elem_bytes, const char* field) {
    if (!read_i32(n, field)) return false;
    return bounded(n, min_elem_bytes, field);
  }
  /// The same for an int16 count (Drake's lcmt_robot_state).
  bool count16(int32_t& n, int64_t min_elem_bytes, const char* field) {
    int16_t n16 = 0;
    if (!read_i16(n16, field)) return false;
    n = n16;
    return bounded(n, min_elem_bytes, field);
  }
  /// Checks a count already read: not negative, and its elements fit in what remains.
  bool bounded(int32_t n, int64_t min_elem_bytes, const char* field) {
    if (n < 0) return fail(std::string(field) + " = " + std::to_string(n) + " is negative");
    if (static_cast<int64_t>(n) * min_elem_bytes > remaining()) {
      return fail(std::string(field) + " = " + std::to_string(n) + " needs at least " +
                  std::to_string(static_cast<int64_t>(n) * min_elem_bytes) + " bytes, " +
                  std::to_string(remaining()) + " left");
    }
    return true;
  }
  bool fail(std::string why) {
    if (error_.empty()) error_ = std::move(why);
    return false;
  }

 private:
  const uint8_t* data_;
  int64_t size_;
  int64_t pos_ = 0;
  std::string error_;
};

constexpr int64_t kMinStringBytes = 5;  // int32 length + NUL

// One function per type: the fields in .lcm order, after the 8-byte fingerprint.
inline bool check_fields(WireReader& r, const robot_state_t*) {
  int64_t i64 = 0;
  int32_t n = 0;
  return r.read_i64(i64, "robot_state_t.utime") && r.string("robot_state_t.robot") &&
         r.count(n, kMinStringBytes, "robot_state_t.num_joints") &&
         [&] {
           for (int32_t i = 0; i < n; ++i)
             if (!r.string("robot_state_t.joint_name")) return false;
           return true;
         }() &&
         r.skip(2 * static_cast<int64_t>(n), 8, "robot_state_t.position/velocity");
}

inline bool check_fields(WireReader& r, const goal_t*) {
  int64_t i64 = 0;
  int32_t n = 0;
  return r.read_i64(i64, "goal_t.utime") && r.read_i64(i64, "goal_t.goal_id") &&
         r.string("goal_t.robot") && r.skip(1, 1, "goal_t.kind") &&
         r.count(n, 8, "goal_t.num_joints") && r.skip(n, 8, "goal_t.joint_position") &&
         r.string("goal_t.ee_frame") && r.skip(3 + 4 + 1, 8, "goal_t.ee_pose/duration_s");
}

// A task constraint inside a goal carries no fingerprint of its own.
inline bool check_fields(WireReader& r, const task_constraint_t*) {
  return r.string("task_constraint_t.frame") && r.boolean("task_constraint_t.orientation_only") &&
         r.skip(3 + 4 + 1, 8, "task_constraint_t.position/quaternion/tolerance");
}
constexpr int64_t kMinTaskConstraintBytes = kMinStringBytes + 1 + 8 * 8;

// goal_v3_t is goal_v2_t's members followed by the tolerances; `type` names the fields.
inline bool check_named_goal_fields(WireReader& r, const std::string& type, bool has_tolerances) {
  const auto f = [&](const char* field) { return type + "." + field; };
  int64_t i64 = 0;
  int32_t n = 0, constraints = 0;
  // Per joint: a name, a position and (version 3) a tolerance.
  const int64_t per_joint = kMinStringBytes + (has_tolerances ? 16 : 8);
  if (!(r.read_i64(i64, f("utime").c_str()) && r.read_i64(i64, f("goal_id").c_str()) &&
        r.string(f("robot").c_str()) && r.skip(1, 1, f("kind").c_str()) &&
        r.count(n, per_joint, f("num_joints").c_str())))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!r.string(f("joint_name").c_str())) return false;
  if (!(r.skip(n, 8, f("joint_position").c_str()) && r.string(f("ee_frame").c_str()) &&
        r.skip(3 + 4, 8, f("ee_position/ee_quaternion").c_str()) &&
        r.boolean(f("position_only").c_str()) && r.skip(1, 8, f("duration_s").c_str()) &&
        r.count(constraints, kMinTaskConstraintBytes, f("num_task_constraints").c_str())))
    return false;
  for (int32_t i = 0; i < constraints; ++i)
    if (!check_fields(r, static_cast<const task_constraint_t*>(nullptr))) return false;
  return !has_tolerances ||
         (r.skip(n, 8, f("joint_tolerance").c_str()) &&
          r.skip(2, 8, f("position_tolerance_m/orientation_tolerance_rad").c_str()));
}
inline bool check_fields(WireReader& r, const goal_v2_t*) {
  return check_named_goal_fields(r, "goal_v2_t", /*has_tolerances=*/false);
}
inline bool check_fields(WireReader& r, const goal_v3_t*) {
  return check_named_goal_fields(r, "goal_v3_t", /*has_tolerances=*/true);
}

inline bool check_fields(WireReader& r, const payload_t*) {
  int64_t i64 = 0;
  return r.read_i64(i64, "payload_t.utime") && r.string("payload_t.robot") &&
         r.skip(1, 1, "payload_t.action") && r.string("payload_t.frame") &&
         r.skip(1 + 3 + 3, 8, "payload_t.mass_kg/size/offset");
}

// A mesh obstacle inside a list carries no fingerprint of its own.
inline bool check_fields(WireReader& r, const mesh_obstacle_t*) {
  return r.string("mesh_obstacle_t.id") && r.skip(1, 1, "mesh_obstacle_t.action") &&
         r.string("mesh_obstacle_t.mesh") &&
         r.skip(3 + 3 + 4, 8, "mesh_obstacle_t.scale/position/quaternion");
}
constexpr int64_t kMinMeshObstacleBytes = 2 * kMinStringBytes + 1 + 10 * 8;

inline bool check_fields(WireReader& r, const mesh_obstacle_list_t*) {
  int64_t i64 = 0;
  int32_t n = 0;
  if (!(r.read_i64(i64, "mesh_obstacle_list_t.utime") &&
        r.string("mesh_obstacle_list_t.source") &&
        r.count(n, kMinMeshObstacleBytes, "mesh_obstacle_list_t.num_obstacles")))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!check_fields(r, static_cast<const mesh_obstacle_t*>(nullptr))) return false;
  return true;
}

// An obstacle inside a list carries no fingerprint of its own.
inline bool check_fields(WireReader& r, const obstacle_t*) {
  return r.string("obstacle_t.id") && r.skip(2, 1, "obstacle_t.action/shape") &&
         r.skip(3 + 3 + 4, 8, "obstacle_t.size/position/quaternion");
}
constexpr int64_t kMinObstacleBytes = kMinStringBytes + 2 + 10 * 8;

// obstacle_list_t (version 2) and obstacle_list_v1_t differ only by the source after utime.
inline bool check_obstacle_list_fields(WireReader& r, bool has_source) {
  int64_t i64 = 0;
  int32_t n = 0;
  if (!r.read_i64(i64, "obstacle_list_t.utime")) return false;
  if (has_source && !r.string("obstacle_list_t.source")) return false;
  if (!r.count(n, kMinObstacleBytes, "obstacle_list_t.num_obstacles")) return false;
  for (int32_t i = 0; i < n; ++i)
    if (!check_fields(r, static_cast<const obstacle_t*>(nullptr))) return false;
  return r.boolean("obstacle_list_t.replace_all");
}
inline bool check_fields(WireReader& r, const obstacle_list_t*) {
  return check_obstacle_list_fields(r, /*has_source=*/true);
}
inline bool check_fields(WireReader& r, const obstacle_list_v1_t*) {
  return check_obstacle_list_fields(r, /*has_source=*/false);
}

// plan_t (version 2) and plan_v1_t differ only by the four clock fields after `method`.
inline bool check_plan_fields(WireReader& r, bool has_clock) {
  int64_t i64 = 0;
  int32_t nj = 0, ns = 0, i32 = 0;
  if (!(r.read_i64(i64, "plan_t.utime") && r.read_i64(i64, "plan_t.plan_id") &&
        r.read_i64(i64, "plan_t.goal_id") && r.string("plan_t.robot") &&
        r.skip(1, 1, "plan_t.status") && r.string("plan_t.status_message") &&
        r.string("plan_t.method")))
    return false;
  if (has_clock && !(r.skip(1, 1, "plan_t.clock") &&
                     r.skip(3, 8, "plan_t.start_utime/state_utime/takeover_utime")))
    return false;
  if (!r.count(nj, kMinStringBytes, "plan_t.num_joints")) return false;
  for (int32_t i = 0; i < nj; ++i)
    if (!r.string("plan_t.joint_name")) return false;
  // t[num_steps] bounds num_steps even when num_joints is 0.
  return r.count(ns, 8, "plan_t.num_steps") && r.skip(ns, 8, "plan_t.t") &&
         r.skip(4 * static_cast<int64_t>(ns) * nj, 8, "plan_t.q/qd/qdd/tau") &&
         r.skip(1, 8, "plan_t.solve_time_s") && r.read_i32(i32, "plan_t.iterations") &&
         r.skip(1 + 4, 8, "plan_t.cost/validation") && r.boolean("plan_t.valid");
}
inline bool check_fields(WireReader& r, const plan_t*) {
  return check_plan_fields(r, /*has_clock=*/true);
}
inline bool check_fields(WireReader& r, const plan_v1_t*) {
  return check_plan_fields(r, /*has_clock=*/false);
}

inline bool check_fields(WireReader& r, const joint_command_t*) {
  int64_t i64 = 0;
  int32_t n = 0;
  if (!(r.read_i64(i64, "joint_command_t.utime") && r.string("joint_command_t.robot") &&
        r.read_i64(i64, "joint_command_t.plan_id") &&
        r.count(n, kMinStringBytes, "joint_command_t.num_joints")))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!r.string("joint_command_t.joint_name")) return false;
  return r.skip(3 * static_cast<int64_t>(n), 8, "joint_command_t.position/velocity/torque");
}

inline bool check_fields(WireReader& r, const stop_request_t*) {
  int64_t i64 = 0;
  return r.read_i64(i64, "stop_request_t.utime") && r.string("stop_request_t.robot") &&
         r.read_i64(i64, "stop_request_t.request_id") && r.string("stop_request_t.reason");
}

inline bool check_fields(WireReader& r, const ::drake::lcmt_iiwa_status*) {
  int64_t i64 = 0;
  int32_t n = 0;
  return r.read_i64(i64, "lcmt_iiwa_status.utime") &&
         r.count(n, 7 * 8, "lcmt_iiwa_status.num_joints") &&
         r.skip(7 * static_cast<int64_t>(n), 8, "lcmt_iiwa_status.joint_*");
}

// A robot state inside a plan carries no fingerprint of its own.
inline bool check_fields(WireReader& r, const ::drake::lcmt_robot_state*) {
  int64_t i64 = 0;
  int32_t n = 0;
  if (!(r.read_i64(i64, "lcmt_robot_state.utime") &&
        r.count16(n, kMinStringBytes + 4, "lcmt_robot_state.num_joints")))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!r.string("lcmt_robot_state.joint_name")) return false;
  return r.skip(n, 4, "lcmt_robot_state.joint_position");
}
constexpr int64_t kMinDrakeStateBytes = 8 + 2;

inline bool check_fields(WireReader& r, const ::drake::lcmt_robot_plan*) {
  int64_t i64 = 0;
  int32_t n = 0;
  if (!(r.read_i64(i64, "lcmt_robot_plan.utime") &&
        r.count(n, kMinDrakeStateBytes, "lcmt_robot_plan.num_states")))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!check_fields(r, static_cast<const ::drake::lcmt_robot_state*>(nullptr))) return false;
  return true;
}

// Version 2's members, which versions 3 and 4 begin with (type names the fields).
inline bool check_status_v2_fields(WireReader& r, const char* type) {
  const std::string t(type);
  int64_t i64 = 0;
  return r.read_i64(i64, (t + ".utime").c_str()) && r.string((t + ".robot").c_str()) &&
         r.skip(1, 1, (t + ".state").c_str()) &&
         r.skip(2, 8, (t + ".last_goal_id/last_plan_id").c_str()) &&
         r.string((t + ".message").c_str()) &&
         r.skip(2, 4, (t + ".num_plans/num_failures").c_str()) &&
         r.skip(4, 8, (t + ".num_goals_*").c_str());
}

inline bool check_fields(WireReader& r, const planner_status_v2_t*) {
  return check_status_v2_fields(r, "planner_status_v2_t");
}

// Version 3's members after version 2's, which version 4 begins with (type names the fields).
inline bool check_status_v3_fields(WireReader& r, const char* type) {
  const std::string t(type);
  return check_status_v2_fields(r, type) && r.string((t + ".model_id").c_str()) &&
         r.skip(7, 8, (t + ".base_position/base_quaternion").c_str()) &&
         r.skip(2, 8, (t + ".goal_utime/valid_plan_id").c_str()) &&
         r.skip(1, 4, (t + ".num_neighbour_replans").c_str()) &&
         r.string((t + ".neighbours").c_str());
}

inline bool check_fields(WireReader& r, const planner_status_v3_t*) {
  return check_status_v3_fields(r, "planner_status_v3_t");
}

inline bool check_fields(WireReader& r, const planner_status_t*) {
  return check_status_v3_fields(r, "planner_status_t") &&
         r.skip(1, 8, "planner_status_t.planning_goal_utime");
}

}  // namespace detail

/// Whether received bytes begin with the fingerprint of `Msg`: tells the versions of a type
/// that share a channel apart (goal_v2_t and goal_t) before decoding.
template <typename Msg>
bool has_fingerprint(const void* data, int size) {
  detail::WireReader reader(data, size);
  int64_t hash = 0;
  return reader.read_i64(hash, "fingerprint") && hash == Msg::getHash();
}

/// Decodes a received kinograph (or Drake) message into `out` (replacing it wholly) only if it is
/// well formed: right fingerprint, every count and string length consistent with the bytes,
/// strings NUL-terminated without inner NULs, booleans 0 or 1, no trailing bytes. On failure `out`
/// is untouched and the status names the bad field. Range checks that need the robot (joint counts,
/// finite values) remain the receiver's job.
template <typename Msg>
DecodeStatus safe_decode(const void* data, int size, Msg& out) {
  detail::WireReader reader(data, size);
  int64_t hash = 0;
  if (!reader.read_i64(hash, "fingerprint")) return {false, reader.error()};
  if (hash != Msg::getHash()) return {false, "fingerprint is not that of the expected type"};
  if (!detail::check_fields(reader, static_cast<const Msg*>(nullptr)))
    return {false, reader.error()};
  if (!reader.at_end())
    return {false, std::to_string(reader.remaining()) + " unexpected bytes after the message"};
  Msg fresh;
  try {
    if (fresh.decode(data, 0, size) != size) return {false, "lcm decode failed"};
  } catch (const std::exception& e) {
    return {false, std::string("lcm decode threw: ") + e.what()};
  }
  out = std::move(fresh);
  return {true, {}};
}

}  // namespace kinograph::lcmtypes
