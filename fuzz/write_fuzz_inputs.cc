// Writes the fuzz targets' generated inputs (fuzz/corpus/README.md):
//   write_fuzz_inputs --seeds DIR        encoded messages of every LCM type (corpus/lcm_messages)
//   write_fuzz_inputs --reproducers DIR  malformed messages issue 20 listed
//   (reproducers/lcm_messages) write_fuzz_inputs --large DIR        the reproducers too large to
//   commit, DIR/<target>/...
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "lcmtypes/sample_messages.h"

namespace {

namespace fs = std::filesystem;
using namespace kinograph::lcmtypes::testing;

void write_file(const fs::path& path, const std::vector<uint8_t>& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

void write_text(const fs::path& path, const std::string& text) {
  write_file(path, std::vector<uint8_t>(text.begin(), text.end()));
}

// Bytes an LCM string takes on the wire: int32 length, the characters, the NUL.
int64_t wire_string(const std::string& s) { return 4 + static_cast<int64_t>(s.size()) + 1; }

// `bytes` with the big-endian int32 at `offset` set to 2^31 - 1 and everything after it cut:
// a count that asks for gigabytes from a message of a few dozen bytes.
std::vector<uint8_t> huge_count_at(std::vector<uint8_t> bytes, int64_t offset) {
  bytes.resize(static_cast<size_t>(offset) + 4);
  const uint32_t n = std::numeric_limits<int32_t>::max();
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<uint8_t>(n >> (8 * (3 - i)));
  return bytes;
}

void write_seeds(const fs::path& dir) {
  write_file(dir / "robot_state_t.bin", encode(make_robot_state()));
  write_file(dir / "goal_t.bin", encode(make_goal()));
  write_file(dir / "goal_v2_t.bin", encode(make_goal_v2()));
  write_file(dir / "obstacle_list_t.bin", encode(make_obstacle_list()));
  write_file(dir / "obstacle_list_v1_t.bin", encode(make_obstacle_list_v1()));
  write_file(dir / "plan_t.bin", encode(make_plan(3)));
  write_file(dir / "plan_v1_t.bin", encode(make_plan_v1(2)));
  write_file(dir / "planner_status_t.bin", encode(make_planner_status()));
  write_file(dir / "joint_command_t.bin", encode(make_joint_command()));
  write_file(dir / "stop_request_t.bin", encode(make_stop_request()));
  write_file(dir / "lcmt_iiwa_status.bin", encode(make_iiwa_status()));
  write_file(dir / "lcmt_robot_plan.bin", encode(make_robot_plan(2)));
}

void write_reproducers(const fs::path& dir) {
  const int64_t fingerprint = 8;
  robot_state_t state = make_robot_state();
  write_file(dir / "robot_state_t_num_joints_2147483647.bin",
             huge_count_at(encode(state), fingerprint + 8 + wire_string(state.robot)));
  goal_t goal = make_goal();
  write_file(dir / "goal_t_num_joints_2147483647.bin",
             huge_count_at(encode(goal), fingerprint + 16 + wire_string(goal.robot) + 1));
  goal_v2_t goal_v2 = make_goal_v2();
  write_file(dir / "goal_v2_t_num_joints_2147483647.bin",
             huge_count_at(encode(goal_v2), fingerprint + 16 + wire_string(goal_v2.robot) + 1));
  obstacle_list_t list = make_obstacle_list();
  write_file(dir / "obstacle_list_t_num_obstacles_2147483647.bin",
             huge_count_at(encode(list), fingerprint + 8 + wire_string(list.source)));
  write_file(dir / "obstacle_list_v1_t_num_obstacles_2147483647.bin",
             huge_count_at(encode(make_obstacle_list_v1()), fingerprint + 8));
  plan_t plan = make_plan(2);
  const int64_t plan_joints = fingerprint + 24 + wire_string(plan.robot) + 1 +
                              wire_string(plan.status_message) + wire_string(plan.method) + 1 + 24;
  write_file(dir / "plan_t_num_joints_2147483647.bin", huge_count_at(encode(plan), plan_joints));
  int64_t plan_steps = plan_joints + 4;
  for (const std::string& name : plan.joint_name) plan_steps += wire_string(name);
  write_file(dir / "plan_t_num_steps_2147483647.bin", huge_count_at(encode(plan), plan_steps));
  joint_command_t command = make_joint_command();
  write_file(dir / "joint_command_t_num_joints_2147483647.bin",
             huge_count_at(encode(command), fingerprint + 8 + wire_string(command.robot) + 8));
  write_file(dir / "lcmt_iiwa_status_num_joints_2147483647.bin",
             huge_count_at(encode(make_iiwa_status()), fingerprint + 8));
  write_file(dir / "lcmt_robot_plan_num_states_2147483647.bin",
             huge_count_at(encode(make_robot_plan(1)), fingerprint + 8));

  // The box of side 1e80 m around the robot that Bullet read as no collision.
  obstacle_list_t room = make_obstacle_list();
  room.obstacles = {make_obstacle("room", obstacle_t::BOX)};
  for (double& x : room.obstacles[0].size) x = 1e80;
  for (double& x : room.obstacles[0].position) x = 0;
  room.num_obstacles = 1;
  write_file(dir / "obstacle_list_t_box_1e80.bin", encode(room));
  obstacle_list_t nan_ball = room;
  nan_ball.obstacles[0].shape = obstacle_t::SPHERE;
  nan_ball.obstacles[0].size[0] = std::numeric_limits<double>::quiet_NaN();
  write_file(dir / "obstacle_list_t_sphere_nan_radius.bin", encode(nan_ball));
  goal_t nan_goal = make_goal();
  nan_goal.ee_position[1] = std::numeric_limits<double>::quiet_NaN();
  write_file(dir / "goal_t_nan_position.bin", encode(nan_goal));
}

// 20,000 spheres in one message and in one scene (the world holds at most 1024).
void write_many_spheres(const fs::path& dir, const std::string& rr_scene) {
  obstacle_list_t list = make_obstacle_list();
  list.obstacles.clear();
  std::string yaml = rr_scene + "obstacles:\n";
  for (int i = 0; i < 20000; ++i) {
    obstacle_t ball = make_obstacle("ball" + std::to_string(i), obstacle_t::SPHERE);
    ball.size[0] = 0.01;
    ball.position[0] = 5 + 0.01 * i;
    list.obstacles.push_back(ball);
    yaml += "  - {id: ball" + std::to_string(i) + ", shape: sphere, size: [0.01], position: [" +
            std::to_string(5 + 0.01 * i) + ", 0, 0]}\n";
  }
  list.num_obstacles = static_cast<int32_t>(list.obstacles.size());
  write_file(dir / "lcm_messages" / "obstacle_list_t_20000_spheres.bin", encode(list));
  write_text(dir / "scene_file" / "obstacles_20000_spheres.yaml", yaml);
  write_text(dir / "change_file" / "obstacles_20000_spheres.yaml",
             yaml.substr(yaml.find("obstacles:\n")));
}

void write_large(const fs::path& dir) {
  const int depth = 50000;
  std::string open, close;
  for (int i = 0; i < depth; ++i) open += "<a>", close += "</a>";
  write_text(dir / "urdf_model" / "nested_50000_elements.urdf",
             "<robot name=\"deep\"><link name=\"base\">" + open + close + "</link></robot>\n");
  const std::string rr_scene =
      "name: deep\nrobot:\n  urdf: ../rr/rr.urdf\nhorizon: 3.0\nsteps: 30\nstart:\n  q: [-1.2, 0]\n"
      "goal:\n  q: [1.2, 0]\n";
  write_text(dir / "scene_file" / "nested_50000_sequences.yaml",
             rr_scene + "limits: " + std::string(depth, '[') + std::string(depth, ']') + "\n");
  write_text(dir / "change_file" / "nested_50000_sequences.yaml",
             "remove: " + std::string(depth, '[') + std::string(depth, ']') + "\n");
  write_text(dir / "plan_file" / "nested_50000_arrays.json",
             "{\"format_version\": 1, \"t\": " + std::string(depth, '[') + std::string(depth, ']') +
                 "}\n");
  write_many_spheres(dir, rr_scene);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: write_fuzz_inputs --seeds|--reproducers|--large DIR\n");
    return 1;
  }
  const std::string mode = argv[1];
  try {
    if (mode == "--seeds") {
      write_seeds(argv[2]);
    } else if (mode == "--reproducers") {
      write_reproducers(argv[2]);
    } else if (mode == "--large") {
      write_large(argv[2]);
    } else {
      std::fprintf(stderr, "write_fuzz_inputs: unknown mode %s\n", mode.c_str());
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_fuzz_inputs: %s\n", e.what());
    return 1;
  }
  return 0;
}
