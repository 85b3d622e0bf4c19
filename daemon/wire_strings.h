#pragma once
// Strings from the wire are written by anyone on the network: they are bounded before the daemon
// echoes them in an answer, a status or its log.
#include <cstddef>
#include <string>

#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/robot_state_t.hpp"

namespace kinograph::daemon {

/// Longest robot, joint, frame or obstacle name accepted from the wire (bytes); a longer one is
/// refused, since it cannot name anything the daemon knows.
constexpr std::size_t kMaxWireName = 256;
/// Longest file path accepted from the wire (bytes; PATH_MAX on Linux).
constexpr std::size_t kMaxWirePath = 4096;
/// Longest piece of a wire string quoted in a reason or log line (bytes) before "…".
constexpr std::size_t kMaxQuoted = 64;

/// `s` cut to at most `max` bytes, on a UTF-8 character boundary, with "…" appended when cut.
std::string truncated(const std::string& s, std::size_t max = kMaxQuoted);

/// Why a message cannot be taken because a name in it is longer than kMaxWireName (the field,
/// its length and its truncated start), or empty.
std::string overlong_name(const goal_t& msg);
std::string overlong_name(const goal_v2_t& msg);
std::string overlong_name(const goal_v3_t& msg);
std::string overlong_name(const payload_t& msg);
/// Mesh paths may be up to kMaxWirePath long.
std::string overlong_name(const mesh_obstacle_list_t& msg);
std::string overlong_name(const robot_state_t& msg);
std::string overlong_name(const obstacle_list_t& msg);

}  // namespace kinograph::daemon
