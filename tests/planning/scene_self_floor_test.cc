// The scene keys of self-collision and the floor: robot.srdf, allowed_collisions,
// self_collision, floor and objectives.self_collision_epsilon, their defaults, round trip and
// errors (file, key, line).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "kinograph/planning/io/scene.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::planning {
namespace {

namespace fs = std::filesystem;

const std::string kScenes = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

std::string scene_with(const std::string& robot_extra, const std::string& extra) {
  return "robot:\n  urdf: robots/iiwa14/iiwa14.urdf\n" + robot_extra +
         "horizon: 2\nsteps: 20\nstart: {q: [0, 0.5, 0, -1, 0, 0.5, 0]}\n"
         "goal: {q: [0.5, 0.5, 0, -1, 0, 0.5, 0]}\n" +
         extra;
}

std::string write_temp(const std::string& name, const std::string& text) {
  static const kinograph::test_support::TempDir dir("kinograph_scene_self_floor_test");
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

std::string error_of(const std::string& yaml) {
  try {
    parse_scene(yaml, "s.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no SceneError";
  return "";
}

TEST(SceneSelfFloor, DefaultsFloorForTheFloorMountedArmOnlySelfOnNothingAllowed) {
  const Scene iiwa = parse_scene(scene_with("", ""));
  EXPECT_EQ(iiwa.problem.self_and_floor.floor, 0.0);
  EXPECT_TRUE(iiwa.problem.self_and_floor.self_collision);
  EXPECT_TRUE(iiwa.problem.self_and_floor.allowed_pairs.empty());
  EXPECT_EQ(iiwa.problem.objectives.self_collision_epsilon, 0.01);
  const Scene acrobot = load_scene(kScenes + "acrobot_swingup.yaml");
  EXPECT_FALSE(acrobot.problem.self_and_floor.floor.has_value());
  const Scene rr = load_scene(kScenes + "rr_reach.yaml");
  EXPECT_FALSE(rr.problem.self_and_floor.floor.has_value());
}

TEST(SceneSelfFloor, ShippedIiwaScenesNameTheSrdf) {
  for (const char* name : {"iiwa_desk.yaml", "iiwa_min_torque.yaml"}) {
    const Scene s = load_scene(kScenes + name);
    EXPECT_EQ(s.problem.self_and_floor.allowed_pairs, (std::vector<std::pair<int, int>>{{4, 6}}))
        << name;
    EXPECT_EQ(s.problem.self_and_floor.floor, 0.0) << name;
  }
}

TEST(SceneSelfFloor, EveryKeyReachesTheProblemAndRoundTrips) {
  const std::string srdf =
      write_temp("a.srdf",
                 "<robot name=\"iiwa14\">\n  <disable_collisions link1=\"iiwa_link_1\" "
                 "link2=\"iiwa_link_3\" reason=\"Never\"/>\n</robot>\n");
  const Scene s = parse_scene(
      scene_with("  srdf: " + srdf + "\n",
                 "self_collision: true\nallowed_collisions:\n  - [iiwa_link_5, iiwa_link_ee]\n"
                 "floor: {height: -0.25}\nobjectives: {self_collision_epsilon: 0.02}\n"));
  const SelfAndFloor& sf = s.problem.self_and_floor;
  EXPECT_EQ(sf.allowed_pairs, (std::vector<std::pair<int, int>>{{0, 2}, {4, 6}}));
  EXPECT_EQ(sf.floor, -0.25);
  EXPECT_EQ(s.problem.objectives.self_collision_epsilon, 0.02);
  EXPECT_EQ(s.allowed_collisions.size(), 1u);
  const Scene back = parse_scene(scene_to_yaml(s));
  EXPECT_EQ(back.srdf_path, s.srdf_path);
  EXPECT_EQ(back.allowed_collisions, s.allowed_collisions);
  EXPECT_EQ(back.problem.self_and_floor.allowed_pairs, sf.allowed_pairs);
  EXPECT_EQ(back.problem.self_and_floor.floor, sf.floor);
  EXPECT_EQ(back.problem.self_and_floor.self_collision, true);
  EXPECT_EQ(back.problem.objectives.self_collision_epsilon, 0.02);
}

TEST(SceneSelfFloor, SwitchesOff) {
  const Scene s = parse_scene(scene_with("", "self_collision: false\nfloor: {enabled: false}\n"));
  EXPECT_FALSE(s.problem.self_and_floor.self_collision);
  EXPECT_FALSE(s.problem.self_and_floor.floor.has_value());
  const Scene back = parse_scene(scene_to_yaml(s));
  EXPECT_FALSE(back.problem.self_and_floor.self_collision);
  EXPECT_FALSE(back.problem.self_and_floor.floor.has_value());
  // A robot without a default floor gets one when asked.
  const Scene rr = parse_scene(
      "robot: {urdf: robots/rr/rr.urdf}\nhorizon: 1\nsteps: 10\nstart: {q: [0, 0]}\n"
      "goal: {q: [0.1, 0]}\nfloor: {enabled: true}\n");
  EXPECT_EQ(rr.problem.self_and_floor.floor, 0.0);
}

TEST(SceneSelfFloor, ErrorsNameKeyAndLine) {
  std::string e = error_of(scene_with("", "allowed_collisions:\n  - [iiwa_link_5, elbow]\n"));
  EXPECT_NE(e.find("line 8"), std::string::npos) << e;
  EXPECT_NE(e.find("'allowed_collisions[0][1]'"), std::string::npos) << e;
  EXPECT_NE(e.find("no frame 'elbow'"), std::string::npos) << e;
  e = error_of(scene_with("", "allowed_collisions: [[iiwa_link_5]]\n"));
  EXPECT_NE(e.find("must be [link, link]"), std::string::npos) << e;
  e = error_of(scene_with("", "floor: {height: abc}\n"));
  EXPECT_NE(e.find("'floor.height'"), std::string::npos) << e;
  e = error_of(scene_with("", "floor: {enabled: false, height: 0.1}\n"));
  EXPECT_NE(e.find("a disabled floor takes no height"), std::string::npos) << e;
  e = error_of(scene_with("", "floor: {level: 0}\n"));
  EXPECT_NE(e.find("'floor.level'"), std::string::npos) << e;
  e = error_of(scene_with("", "self_collision: maybe\n"));
  EXPECT_NE(e.find("must be true or false"), std::string::npos) << e;
  e = error_of(scene_with("  srdf: /nonexistent.srdf\n", ""));
  EXPECT_NE(e.find("'robot.srdf'"), std::string::npos) << e;
  const std::string bad = write_temp("bad.srdf", "<robot>\n  <disable_collisions link1=\"x\"\n");
  e = error_of(scene_with("  srdf: " + bad + "\n", ""));
  EXPECT_NE(e.find("line 3"), std::string::npos) << e;          // the scene's line of robot.srdf
  EXPECT_NE(e.find("bad.srdf' line"), std::string::npos) << e;  // and the SRDF's own
}

}  // namespace
}  // namespace kinograph::planning
