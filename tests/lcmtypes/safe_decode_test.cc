// safe_decode: accepts every well-formed message, rejects malformed ones with a reason and
// without throwing or allocating from untrusted counts, and never hands back stale arrays.
#include "lcmtypes/safe_decode.h"

#include <gtest/gtest.h>

#include <climits>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "tests/lcmtypes/sample_messages.h"

namespace {

using kinograph::goal_t;
using kinograph::obstacle_list_t;
using kinograph::obstacle_t;
using kinograph::plan_t;
using kinograph::planner_status_t;
using kinograph::robot_state_t;
using kinograph::goal_v2_t;
using kinograph::lcmtypes::DecodeStatus;
using kinograph::lcmtypes::has_fingerprint;
using kinograph::lcmtypes::safe_decode;
using namespace kinograph::lcmtypes::testing;

template <typename Msg>
DecodeStatus decode_bytes(const std::vector<uint8_t>& bytes, Msg& out) {
  return safe_decode(bytes.data(), static_cast<int>(bytes.size()), out);
}

void put_i32(std::vector<uint8_t>& bytes, size_t offset, int32_t value) {
  const uint32_t u = static_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<uint8_t>(u >> (24 - 8 * i));
}

// Byte offset of robot_state_t.num_joints: fingerprint, utime, robot (length + "iiwa14\0").
constexpr size_t kNumJointsOffset = 8 + 8 + 4 + 7;

template <typename Msg>
void expect_accepts(const Msg& m) {
  const std::vector<uint8_t> bytes = encode(m);
  Msg out;
  const DecodeStatus status = decode_bytes(bytes, out);
  EXPECT_TRUE(status.ok) << status.reason;
  EXPECT_EQ(encode(out), bytes);
}

TEST(SafeDecode, AcceptsWellFormedMessagesOfEveryType) {
  expect_accepts(make_robot_state());
  expect_accepts(make_goal());
  goal_t joint_goal = make_goal();
  joint_goal.joint_position = {0.1, 0.2, 0.3};
  joint_goal.num_joints = 3;
  expect_accepts(joint_goal);
  expect_accepts(make_goal_v2());
  expect_accepts(make_goal_v3());
  expect_accepts(make_payload());
  expect_accepts(make_mesh_obstacle_list());
  expect_accepts(make_obstacle("o", obstacle_t::CYLINDER));
  expect_accepts(make_obstacle_list());
  expect_accepts(make_obstacle_list_v1());
  expect_accepts(make_plan(6));
  expect_accepts(make_plan(0));
  expect_accepts(make_plan_v1(6));
  expect_accepts(make_planner_status());
  expect_accepts(make_joint_command());
  expect_accepts(make_stop_request());
  expect_accepts(make_iiwa_status());
  expect_accepts(make_robot_plan(5));
  expect_accepts(make_robot_plan(0));
}

template <typename Msg>
void expect_prefixes_rejected(const Msg& m) {
  const std::vector<uint8_t> bytes = encode(m);
  for (size_t len = 0; len < bytes.size(); ++len) {
    const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + len);
    Msg out;
    const DecodeStatus status = decode_bytes(prefix, out);
    EXPECT_FALSE(status.ok) << "prefix length " << len;
    EXPECT_FALSE(status.reason.empty());
  }
}

TEST(SafeDecode, RejectsEveryTruncation) {
  expect_prefixes_rejected(make_robot_state());
  expect_prefixes_rejected(make_goal());
  expect_prefixes_rejected(make_goal_v2());
  expect_prefixes_rejected(make_goal_v3());
  expect_prefixes_rejected(make_payload());
  expect_prefixes_rejected(make_mesh_obstacle_list());
  expect_prefixes_rejected(make_obstacle_list());
  expect_prefixes_rejected(make_obstacle_list_v1());
  expect_prefixes_rejected(make_plan(3));
  expect_prefixes_rejected(make_plan_v1(3));
  expect_prefixes_rejected(make_planner_status());
  expect_prefixes_rejected(make_joint_command());
  expect_prefixes_rejected(make_stop_request());
  expect_prefixes_rejected(make_iiwa_status());
  expect_prefixes_rejected(make_robot_plan(3));
}

// Both goal versions come on one channel: the fingerprint tells them apart before decoding.
TEST(SafeDecode, TellsTheGoalVersionsApart) {
  const std::vector<uint8_t> v1 = encode(make_goal()), v2 = encode(make_goal_v2());
  const int n1 = static_cast<int>(v1.size()), n2 = static_cast<int>(v2.size());
  EXPECT_TRUE(has_fingerprint<goal_t>(v1.data(), n1));
  EXPECT_FALSE(has_fingerprint<goal_v2_t>(v1.data(), n1));
  EXPECT_TRUE(has_fingerprint<goal_v2_t>(v2.data(), n2));
  EXPECT_FALSE(has_fingerprint<goal_t>(v2.data(), n2));
  EXPECT_FALSE(has_fingerprint<goal_t>(v1.data(), 7));  // shorter than a fingerprint
  goal_t as_v1;
  EXPECT_FALSE(decode_bytes(v2, as_v1).ok);
}

// The three goal versions and the two obstacle list kinds share channels: each fingerprint is
// its own, so none is taken for another.
TEST(SafeDecode, TellsTheNewerGoalAndMeshListApart) {
  const std::vector<uint8_t> v2 = encode(make_goal_v2()), v3 = encode(make_goal_v3());
  const std::vector<uint8_t> meshes = encode(make_mesh_obstacle_list());
  EXPECT_TRUE(has_fingerprint<goal_v3_t>(v3.data(), static_cast<int>(v3.size())));
  EXPECT_FALSE(has_fingerprint<goal_v2_t>(v3.data(), static_cast<int>(v3.size())));
  EXPECT_FALSE(has_fingerprint<goal_v3_t>(v2.data(), static_cast<int>(v2.size())));
  EXPECT_TRUE(has_fingerprint<mesh_obstacle_list_t>(meshes.data(), static_cast<int>(meshes.size())));
  obstacle_list_t as_list;
  EXPECT_FALSE(decode_bytes(meshes, as_list).ok);
  goal_v2_t as_v2;
  EXPECT_FALSE(decode_bytes(v3, as_v2).ok);
}

// The two versions of plan_t have their own fingerprints: neither decodes as the other.
TEST(SafeDecode, TellsThePlanVersionsApart) {
  plan_t v2;
  kinograph::plan_v1_t v1;
  const DecodeStatus as_v2 = decode_bytes(encode(make_plan_v1(2)), v2);
  EXPECT_FALSE(as_v2.ok);
  EXPECT_NE(as_v2.reason.find("fingerprint"), std::string::npos) << as_v2.reason;
  EXPECT_FALSE(decode_bytes(encode(make_plan(2)), v1).ok);
  EXPECT_TRUE(decode_bytes(encode(make_plan_v1(2)), v1).ok);
}

// So have the two versions of obstacle_list_t.
TEST(SafeDecode, TellsTheObstacleListVersionsApart) {
  obstacle_list_t v2;
  kinograph::obstacle_list_v1_t v1;
  const DecodeStatus as_v2 = decode_bytes(encode(make_obstacle_list_v1()), v2);
  EXPECT_FALSE(as_v2.ok);
  EXPECT_NE(as_v2.reason.find("fingerprint"), std::string::npos) << as_v2.reason;
  EXPECT_FALSE(decode_bytes(encode(make_obstacle_list()), v1).ok);
  EXPECT_TRUE(decode_bytes(encode(make_obstacle_list_v1()), v1).ok);
}

// Drake's lcmt_robot_state counts joints in an int16: a negative count is refused by name.
TEST(SafeDecode, RejectsANegativeDrakeJointCount) {
  std::vector<uint8_t> bytes = encode(make_robot_plan(1));
  // fingerprint, plan utime, num_states, then the first knot's utime and its int16 count.
  const size_t offset = 8 + 8 + 4 + 8;
  bytes[offset] = 0xff;
  bytes[offset + 1] = 0xfe;
  drake::lcmt_robot_plan out;
  const DecodeStatus status = decode_bytes(bytes, out);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.reason.find("lcmt_robot_state.num_joints = -2"), std::string::npos)
      << status.reason;
}

// lcm-gen's decode would resize to these counts before looking at the bytes (or throw).
TEST(SafeDecode, RejectsNegativeAndHugeCountsNamingTheField) {
  robot_state_t m = make_robot_state();
  for (const int32_t count : {-1, INT_MIN, 10'000'000, INT_MAX}) {
    std::vector<uint8_t> bytes = encode(m);
    put_i32(bytes, kNumJointsOffset, count);
    robot_state_t out;
    const DecodeStatus status = decode_bytes(bytes, out);
    EXPECT_FALSE(status.ok) << count;
    EXPECT_NE(status.reason.find("robot_state_t.num_joints"), std::string::npos) << status.reason;
    EXPECT_TRUE(out.joint_name.empty());
  }
}

TEST(SafeDecode, RejectsBadStringLengthsAndTerminators) {
  const robot_state_t m = make_robot_state();
  for (const int32_t len : {0, -5, 1'000'000}) {
    std::vector<uint8_t> bytes = encode(m);
    put_i32(bytes, 16, len);  // robot's length field
    robot_state_t out;
    const DecodeStatus status = decode_bytes(bytes, out);
    EXPECT_FALSE(status.ok) << len;
    EXPECT_NE(status.reason.find("robot_state_t.robot"), std::string::npos) << status.reason;
  }
  std::vector<uint8_t> bytes = encode(m);
  bytes[kNumJointsOffset - 1] = 'x';  // the robot name's NUL
  robot_state_t out;
  EXPECT_FALSE(decode_bytes(bytes, out).ok);
}

TEST(SafeDecode, RejectsBooleansOtherThanZeroOrOne) {
  std::vector<uint8_t> bytes = encode(make_plan(2));
  ASSERT_EQ(bytes.back(), 1);  // plan_t.valid is the last field
  bytes.back() = 2;
  plan_t out;
  const DecodeStatus status = decode_bytes(bytes, out);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.reason.find("plan_t.valid"), std::string::npos) << status.reason;
}

TEST(SafeDecode, RejectsTrailingBytesAndOtherTypes) {
  std::vector<uint8_t> bytes = encode(make_goal());
  bytes.push_back(0);
  goal_t goal;
  EXPECT_FALSE(decode_bytes(bytes, goal).ok);
  bytes.pop_back();
  plan_t plan;
  const DecodeStatus status = decode_bytes(bytes, plan);
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.reason.find("fingerprint"), std::string::npos);
}

// Raw lcm-gen decode keeps an array's old contents when the new count is 0; safe_decode
// replaces the whole object, and leaves it untouched on failure.
TEST(SafeDecode, ReplacesTheWholeObjectOrNothing) {
  robot_state_t out = make_robot_state();
  robot_state_t empty = make_robot_state();
  empty.num_joints = 0;
  empty.joint_name.clear();
  empty.position.clear();
  empty.velocity.clear();
  ASSERT_TRUE(decode_bytes(encode(empty), out).ok);
  EXPECT_TRUE(out.position.empty());
  EXPECT_TRUE(out.joint_name.empty());

  const robot_state_t before = make_robot_state();
  out = before;
  std::vector<uint8_t> bad = encode(empty);
  bad.resize(bad.size() - 1);
  EXPECT_FALSE(decode_bytes(bad, out).ok);
  EXPECT_EQ(encode(out), encode(before));
}

// Random corruption never crashes or throws, and whatever is accepted re-encodes to exactly
// the bytes received (nothing was silently dropped or invented).
template <typename Msg>
void fuzz(const Msg& m, std::mt19937& engine, int trials) {
  const std::vector<uint8_t> clean = encode(m);
  std::uniform_int_distribution<size_t> position(0, clean.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255), flips(1, 3);
  int accepted = 0;
  for (int t = 0; t < trials; ++t) {
    std::vector<uint8_t> bytes = clean;
    for (int f = flips(engine); f > 0; --f) bytes[position(engine)] = byte(engine);
    Msg out;
    DecodeStatus status;
    EXPECT_NO_THROW(status = decode_bytes(bytes, out));
    if (status.ok) {
      ++accepted;
      EXPECT_EQ(encode(out), bytes);
    } else {
      EXPECT_FALSE(status.reason.empty());
    }
  }
  // Most flips land in doubles, which any bit pattern is: some mutants must be accepted.
  EXPECT_GT(accepted, 0);
}

TEST(SafeDecode, SurvivesRandomCorruption) {
  std::mt19937 engine(4242);
  fuzz(make_robot_state(), engine, 2000);
  fuzz(make_goal(), engine, 2000);
  fuzz(make_goal_v2(), engine, 2000);
  fuzz(make_goal_v3(), engine, 2000);
  fuzz(make_payload(), engine, 2000);
  fuzz(make_mesh_obstacle_list(), engine, 2000);
  fuzz(make_obstacle_list(), engine, 2000);
  fuzz(make_plan(3), engine, 2000);
  fuzz(make_planner_status(), engine, 2000);
}

}  // namespace
