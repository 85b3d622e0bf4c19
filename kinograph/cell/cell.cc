#include "kinograph/cell/cell.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "kinograph/dynamics/model_compose.h"
#include "kinograph/planning/io/yaml_reader.h"

namespace kinograph::cell {
namespace {

namespace fs = std::filesystem;
using planning::yaml::index_key;
using planning::yaml::Reader;

// Keys the robots share, written once at the top of a cell in the scene file's form.
constexpr std::initializer_list<const char*> kSharedKeys = {
    "horizon", "steps", "obstacles", "floor", "objectives", "planner", "camera", "self_collision"};
// Keys of one robot's entry; all but `name` are the scene file's keys of that name.
constexpr std::initializer_list<const char*> kRobotKeys = {"name",
                                                           "robot",
                                                           "start",
                                                           "goal",
                                                           "limits",
                                                           "unactuated",
                                                           "allowed_collisions",
                                                           "task_constraints"};

bool is_robot_key(const std::string& key) {
  for (const char* k : kRobotKeys) {
    if (key == k) return true;
  }
  return false;
}

// The cell's key path of a key path of robot `i`'s scene: its own keys live in its entry.
std::string robot_key_path(std::size_t i, const std::string& scene_key) {
  const std::string entry = index_key("robots", i);
  if (scene_key.empty()) return entry;
  const std::string head = scene_key.substr(0, scene_key.find_first_of(".["));
  return is_robot_key(head) ? entry + "." + scene_key : scene_key;
}

CellRobot parse_robot(const Reader& r, const YAML::Node& root, const YAML::Node& entry,
                      std::size_t i, const std::string& cell_name) {
  const std::string key = index_key("robots", i);
  r.expect_map(entry, key, kRobotKeys);
  CellRobot robot;
  robot.name = r.string(r.required(entry, key, "name"), key + ".name");
  if (robot.name.find(dynamics::kComposeSeparator) != std::string::npos) {
    r.fail(entry["name"], key + ".name",
           "must not contain '" + std::string(1, dynamics::kComposeSeparator) +
               "' (it separates the robot's name from its joints' in the centralized plan)");
  }
  for (const char* k : {"robot", "start", "goal"}) r.required(entry, key, k);
  // The robot's scene is the shared keys with its own; the nodes keep their lines.
  YAML::Node scene(YAML::NodeType::Map);
  scene["name"] = cell_name + "." + robot.name;
  for (const char* k : kSharedKeys) {
    if (root[k]) scene[k] = root[k];
  }
  for (const auto& child : entry) {
    if (child.first.Scalar() != "name") scene[child.first.Scalar()] = child.second;
  }
  robot.scene = planning::yaml::parse_scene_tree(
      scene, r.file(), [i](const std::string& k) { return robot_key_path(i, k); });
  return robot;
}

}  // namespace

int Cell::robot_index(const std::string& robot) const {
  for (std::size_t i = 0; i < robots.size(); ++i) {
    if (robots[i].name == robot) return static_cast<int>(i);
  }
  throw std::out_of_range("no robot '" + robot + "' in the cell '" + name + "'");
}

Cell parse_cell(const std::string& yaml, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw planning::SceneError(source, "", e.mark.is_null() ? 0 : e.mark.line + 1,
                               "not valid YAML: " + e.msg);
  }
  const Reader r(source);
  if (!root.IsDefined() || root.IsNull()) r.fail(root, "", "the file is empty");
  r.expect_map(root, "",
               {"name", "horizon", "steps", "obstacles", "floor", "objectives", "planner", "camera",
                "self_collision", "robots"});
  Cell cell;
  cell.source = source;
  cell.name = root["name"] ? r.string(root["name"], "name")
                           : (source.empty() ? "cell" : fs::path(source).stem().string());
  for (const char* k : {"horizon", "steps"}) r.required(root, "", k);
  const YAML::Node robots = r.required(root, "", "robots");
  if (!robots.IsSequence() || robots.size() == 0) {
    r.fail(robots, "robots", "must be a list of at least one robot");
  }
  for (std::size_t i = 0; i < robots.size(); ++i) {
    CellRobot robot = parse_robot(r, root, robots[i], i, cell.name);
    for (const CellRobot& other : cell.robots) {
      if (other.name == robot.name) {
        r.fail(robots[i]["name"], index_key("robots", i) + ".name",
               "two robots are named '" + robot.name + "'");
      }
    }
    cell.robots.push_back(std::move(robot));
  }
  return cell;
}

Cell load_cell(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw planning::SceneError(path, "", 0, "cannot open the file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_cell(text.str(), path);
}

}  // namespace kinograph::cell
