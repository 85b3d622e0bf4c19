// LCM verbs of the CLI: talk to a running kinographd.
//   kinograph send-goal     --prefix IIWA (--q ... | --joint NAME=V ... | --frame F
//                           --position ... (--quaternion ... | --position-only)) [--utime US]
//                           [--joint-tolerance NAME=T ... | --position-tolerance M
//                           --orientation-tolerance RAD]
//   kinograph send-obstacle --prefix IIWA --id box --shape box --size ... --position ...
//                           [--utime US] [--source NAME [--replace-all]]; --shape mesh
//                           --mesh FILE [--scale ...]
//   kinograph send-payload  --prefix IIWA (--frame F --mass KG --size ... [--offset ...] |
//                           --detach)
//   kinograph send-state    --prefix IIWA --scene S --q ... [--qd ...] [--utime US]
//   kinograph send-raw      CHANNEL --text BYTES
//   kinograph log-plans     LOG.lcmlog --channel IIWA_PLAN --scene S --out-dir DIR
//                           [--obstacles-channel IIWA_OBSTACLES]
// send-goal and send-obstacle can wait for the answering plan (--wait) and write it (--out).
// --utime stamps a message on the robot's clock (e.g. sim time) instead of the wall clock.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/goal_v3_t.hpp"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/mesh_obstacle_list_t.hpp"
#include "kinograph/obstacle_list_t.hpp"
#include "kinograph/obstacle_list_v1_t.hpp"
#include "kinograph/payload_t.hpp"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"
#include "tools/command_registry.h"
#include "tools/lcm_client.h"
#include "tools/number_list.h"
#include "tools/plan_file.h"

namespace kinograph::tools {

PlanWaiter::PlanWaiter(lcm::LCM& lcm, const std::string& plan_channel) : lcm_(lcm) {
  lcm_.subscribe(plan_channel, &PlanWaiter::on_plan, this);
}

void PlanWaiter::on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
  plan_t msg;
  if (!lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), msg).ok) return;
  if (msg.goal_id == goal_id_ && !received_) received_ = std::move(msg);
}

std::optional<plan_t> PlanWaiter::wait(int64_t goal_id, double timeout_s) {
  goal_id_ = goal_id;
  received_.reset();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!received_ && std::chrono::steady_clock::now() < deadline) {
    if (lcm_.handleTimeout(20) < 0) break;
  }
  return std::move(received_);
}

lcm::LCM& open_lcm(const std::string& url) {
  static std::unique_ptr<lcm::LCM> lcm;
  lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw CommandFailure("LCM could not start on \"" + (url.empty() ? "default URL" : url) +
                         "\" (udpm needs a multicast route)");
  }
  return *lcm;
}

namespace {

// Both plan versions share these fields.
template <typename PlanMessage>
std::string summarize_plan(const PlanMessage& p) {
  static const char* kStatus[] = {"SUCCESS",   "FAILED",        "INVALID_GOAL", "INVALID_STATE",
                                  "CANCELLED", "NOT_CONVERGED", "SUPERSEDED"};
  std::ostringstream s;
  s << "plan " << p.plan_id << " for goal " << p.goal_id << ": "
    << (p.status >= 0 && p.status <= plan_t::SUPERSEDED ? kStatus[p.status] : "UNKNOWN");
  if (!p.status_message.empty()) s << " (" << p.status_message << ")";
  if (p.num_steps > 0) {
    s << "\n  method " << p.method << ", " << p.num_steps << " states, " << p.iterations
      << " iterations, " << p.solve_time_s * 1e3 << " ms, cost " << p.cost
      << "\n  dynamics residual " << p.max_dynamics_residual << " N·m, collocation "
      << p.max_collocation_residual << ", min clearance " << p.min_clearance << " m, goal error "
      << p.goal_error << ", valid " << (p.valid ? "yes" : "no");
  }
  return s.str();
}

}  // namespace

std::string summarize(const plan_t& p) {
  std::ostringstream s;
  s << summarize_plan(p) << "\n  clock " << (p.clock == plan_t::CLOCK_ROBOT ? "robot" : "wall")
    << ", published at " << p.utime << " us";
  if (p.num_steps > 0) s << ", starts at " << p.start_utime << " us";
  s << (p.state_utime >= 0 ? ", from the state at " + std::to_string(p.state_utime) + " us"
                           : ", from the scene's start");
  return s.str();
}

std::string summarize(const plan_v1_t& p) {
  return summarize_plan(p) + "\n  (plan_t version 1: no clock; times are from the plan's start)";
}

namespace {

std::string join_names(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) {
    if (!text.empty()) text += ", ";
    text += n;
  }
  return text;
}

int64_t now_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

// Options every sending verb has.
struct Common {
  std::string prefix, url, scene, out;
  double wait_s = 0;
  void add(CLI::App* sub, bool waits) {
    sub->add_option("--prefix", prefix, "channel prefix of the daemon, e.g. IIWA")->required();
    sub->add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
    if (!waits) return;
    sub->add_option("--wait", wait_s, "wait this many seconds for the answering plan");
    sub->add_option("--out", out, "write the answering plan as JSON (needs --wait and --scene)");
    sub->add_option("--scene", scene, "the daemon's scene (robot for --out)");
  }
  // The scene --out writes plans for, read before anything is sent so that a command that
  // cannot finish sends nothing. @throws CommandFailure for --out without --wait or --scene.
  std::optional<planning::Scene> output_scene() const {
    if (out.empty()) return std::nullopt;
    if (scene.empty()) throw CommandFailure("--out needs --scene (the robot the plan file names)");
    if (wait_s <= 0) throw CommandFailure("--out needs --wait (how long to wait for the plan)");
    try {
      return planning::load_scene(scene);
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
  }
};

// Adds an obstacle received over LCM to the scene a plan file is written for.
void add_obstacle(planning::Scene& scene, const std::string& name, collision::Obstacle obstacle) {
  obstacle.id = static_cast<int>(scene.problem.obstacles.size());
  scene.obstacle_names.push_back(name);
  scene.problem.obstacles.push_back(std::move(obstacle));
}

// Waits for the plan answering goal_id, prints it, writes it to c.out for `scene` if asked;
// returns the exit code. `extra` is an obstacle this command sent, written into the plan file
// with the scene's own.
int finish(PlanWaiter& waiter, const Common& c, int64_t goal_id,
           std::optional<planning::Scene> scene,
           const std::optional<std::pair<std::string, collision::Obstacle>>& extra = {}) {
  if (c.wait_s <= 0) return 0;
  auto plan = waiter.wait(goal_id, c.wait_s);
  if (!plan) {
    throw CommandFailure("no plan for goal " + std::to_string(goal_id) + " within " +
                             std::to_string(c.wait_s) + " s",
                         kExitTimeout);
  }
  std::cout << summarize(*plan) << "\n";
  if (scene) {
    if (extra) add_obstacle(*scene, extra->first, extra->second);
    if (plan->num_steps == 0)
      throw CommandFailure("plan has no trajectory to write", kExitInvalidPlan);
    nlohmann::json json = planning::plan_to_json(messages::plan_from_message(*plan), *scene);
    json["start_utime"] = plan->start_utime;  // knot 0 on the robot's clock (check-together)
    write_plan_json(std::move(json), *scene, c.out);
    std::cout << "wrote " << c.out << "\n";
  }
  return plan->status == plan_t::SUCCESS ? kExitOk : kExitInvalidPlan;
}

// "NAME=VALUE" of --joint; the value may use pi. @throws CommandFailure naming the item.
std::pair<std::string, double> parse_named_joint(const std::string& item) {
  const std::size_t eq = item.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw CommandFailure("--joint: '" + item + "' is not NAME=VALUE (e.g. iiwa_joint_2=pi/4)");
  }
  const std::string name = item.substr(0, eq);
  return {name, parse_number_list(item.substr(eq + 1), "--joint " + name, 1)[0]};
}

// What send-goal's options say about a goal of version 2 or later.
struct NamedGoalOptions {
  std::vector<std::string> joints;
  std::string frame, position, quaternion;
  bool position_only = false;
};

// Fills the members goal_v2_t and goal_v3_t share from the options. @throws CommandFailure for
// an incomplete pose goal or a malformed value.
template <class GoalMessage>
void fill_named_goal(const NamedGoalOptions& o, GoalMessage& g) {
  g.ee_quaternion[0] = 1;
  if (!o.joints.empty()) {
    g.kind = GoalMessage::KIND_JOINT_CONFIGURATION;
    for (const std::string& item : o.joints) {
      const auto [name, value] = parse_named_joint(item);
      g.joint_name.push_back(name);
      g.joint_position.push_back(value);
    }
    g.num_joints = static_cast<int32_t>(g.joint_name.size());
    return;
  }
  if (o.frame.empty() || o.position.empty() || (o.quaternion.empty() && !o.position_only)) {
    throw CommandFailure(
        "send-goal: a pose goal needs --frame, --position and --quaternion "
        "(--quaternion 1,0,0,0 keeps the world's axes; --position-only ignores it)");
  }
  if (o.position_only && !o.quaternion.empty()) {
    throw CommandFailure("send-goal: --position-only ignores the orientation: drop --quaternion");
  }
  g.kind = GoalMessage::KIND_END_EFFECTOR_POSE;
  g.ee_frame = o.frame;
  g.position_only = o.position_only;
  auto p = parse_number_list(o.position, "--position", 3);
  std::copy(p.begin(), p.end(), g.ee_position);
  if (!o.quaternion.empty()) {
    auto r = parse_number_list(o.quaternion, "--quaternion", 4);
    std::copy(r.begin(), r.end(), g.ee_quaternion);
  }
}

// What send-goal's tolerance options say.
struct ToleranceOptions {
  std::vector<std::string> joints;  // NAME=VALUE
  double position = 0, orientation = 0;
  bool given() const { return !joints.empty() || position != 0 || orientation != 0; }
};

// The goal_v3_t tolerances of a goal filled by fill_named_goal. @throws CommandFailure for a
// joint tolerance of a joint the goal does not name, or tolerances of the other goal kind.
void fill_tolerances(const ToleranceOptions& t, goal_v3_t& g) {
  const bool joint_goal = g.kind == goal_v3_t::KIND_JOINT_CONFIGURATION;
  if (joint_goal && (t.position != 0 || t.orientation != 0)) {
    throw CommandFailure("send-goal: --position-tolerance and --orientation-tolerance are for "
                         "pose goals; a joint goal takes --joint-tolerance NAME=VALUE");
  }
  if (!joint_goal && !t.joints.empty()) {
    throw CommandFailure("send-goal: --joint-tolerance is for joint goals (--joint)");
  }
  g.joint_tolerance.assign(g.joint_name.size(), 0.0);
  for (const std::string& item : t.joints) {
    const auto [name, value] = parse_named_joint(item);
    const auto it = std::find(g.joint_name.begin(), g.joint_name.end(), name);
    if (it == g.joint_name.end()) {
      throw CommandFailure("send-goal: --joint-tolerance " + name +
                           " names a joint the goal does not move (give it with --joint)");
    }
    g.joint_tolerance[static_cast<std::size_t>(it - g.joint_name.begin())] = value;
  }
  g.position_tolerance_m = t.position;
  g.orientation_tolerance_rad = t.orientation;
}

const bool kSendGoal = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "send-goal",
      "publish a goal to a kinographd (goal_t for --q, goal_v3_t with tolerances, goal_v2_t "
      "otherwise)");
  auto c = std::make_shared<Common>();
  auto q = std::make_shared<std::string>();
  auto named = std::make_shared<NamedGoalOptions>();
  auto tolerance = std::make_shared<ToleranceOptions>();
  auto goal_id = std::make_shared<int64_t>(-1);
  auto duration = std::make_shared<double>(0);
  auto robot = std::make_shared<std::string>();
  auto utime = std::make_shared<int64_t>(-1);
  c->add(sub, true);
  sub->add_option("--id", *goal_id, "goal id (default: current time in µs)");
  sub->add_option("--utime", *utime,
                  "goal time on the robot's clock (µs), e.g. sim time (default: the wall clock)");
  sub->add_option("--q", *q,
                  "joint goal (rad), every joint in URDF order, comma-separated; angles may "
                  "use pi");
  sub->add_option("--joint", named->joints,
                  "joint goal by name, NAME=VALUE (rad), repeatable; joints not named are held "
                  "at their start");
  sub->add_option("--frame", named->frame, "end-effector frame for a pose goal");
  sub->add_option("--position", named->position, "pose goal position x,y,z (m)");
  sub->add_option("--quaternion", named->quaternion,
                  "pose goal orientation w,x,y,z (required with --frame unless --position-only; "
                  "1,0,0,0 = the world's axes)");
  sub->add_flag("--position-only", named->position_only,
                "pose goal: reach --position in any orientation");
  sub->add_option("--joint-tolerance", tolerance->joints,
                  "joint goal: how far joint NAME may end from its goal, NAME=VALUE (rad), "
                  "repeatable (default 0.01)");
  sub->add_option("--position-tolerance", tolerance->position,
                  "pose goal: how far the frame may end from --position (m, default 0.01)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--orientation-tolerance", tolerance->orientation,
                  "pose goal: how far its orientation may end from --quaternion (rad, default "
                  "0.01)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--duration", *duration, "plan duration (s), 0 = the daemon's default");
  sub->add_option("--robot", *robot, "robot name in the message (default: empty = any)");
  sub->callback([=] {
    const bool pose = !named->frame.empty() || !named->position.empty() ||
                      !named->quaternion.empty();
    const int kinds = !q->empty() + !named->joints.empty() + pose;
    if (kinds > 1) {
      throw CommandFailure(
          "send-goal: give one goal: --q, --joint, or a pose goal (--frame, --position, "
          "--quaternion), not both");
    }
    if (kinds == 0) {
      throw CommandFailure(
          "send-goal needs --q, --joint, or --frame with --position and --quaternion");
    }
    if (named->position_only && !pose) throw CommandFailure("--position-only is for pose goals");
    if (!q->empty() && tolerance->given()) {
      throw CommandFailure("send-goal: --q sends goal_t, which has no tolerances: name the "
                           "joints with --joint NAME=VALUE and give --joint-tolerance");
    }
    const int64_t id = *goal_id >= 0 ? *goal_id : now_utime();
    const int64_t when = *utime >= 0 ? *utime : now_utime();
    // Every joint in URDF order is what the first goal type says; names need version 2, and
    // tolerances version 3.
    const auto header = [&](auto& g) {
      g.utime = when;
      g.goal_id = id;
      g.robot = *robot;
      g.duration_s = *duration;
    };
    goal_t v1{};
    goal_v2_t v2{};
    goal_v3_t v3{};
    const char* type = "goal_v2_t";
    if (!q->empty()) {
      header(v1);
      v1.ee_quaternion[0] = 1;
      v1.kind = goal_t::KIND_JOINT_CONFIGURATION;
      v1.joint_position = parse_number_list(*q, "--q");
      v1.num_joints = static_cast<int32_t>(v1.joint_position.size());
      type = "goal_t";
    } else if (tolerance->given()) {
      header(v3);
      fill_named_goal(*named, v3);
      fill_tolerances(*tolerance, v3);
      type = "goal_v3_t";
    } else {
      header(v2);
      fill_named_goal(*named, v2);
    }
    std::optional<planning::Scene> scene = c->output_scene();
    lcm::LCM& lcm = open_lcm(c->url);
    PlanWaiter waiter(lcm, c->prefix + "_PLAN");
    if (type == std::string("goal_t")) {
      lcm.publish(c->prefix + "_GOAL", &v1);
    } else if (type == std::string("goal_v3_t")) {
      lcm.publish(c->prefix + "_GOAL", &v3);
    } else {
      lcm.publish(c->prefix + "_GOAL", &v2);
    }
    std::cout << "sent goal " << id << " on " << c->prefix << "_GOAL (" << type << ")\n";
    if (int code = finish(waiter, *c, id, std::move(scene)); code != 0) {
      throw CommandFailure("", code);
    }
  });
});

// The mesh_obstacle_list_t of send-obstacle --shape mesh.
mesh_obstacle_list_t mesh_obstacle_message(const std::string& id, bool remove,
                                           const std::string& mesh, const std::string& scale,
                                           const std::vector<double>& position,
                                           const std::vector<double>& quaternion) {
  mesh_obstacle_t o{};
  o.id = id;
  o.action = remove ? mesh_obstacle_t::REMOVE : mesh_obstacle_t::ADD_OR_MOVE;
  o.mesh = mesh;
  const std::vector<double> k = parse_number_list(scale, "--scale", 3);
  std::copy(k.begin(), k.end(), o.scale);
  std::copy(position.begin(), position.end(), o.position);
  std::copy(quaternion.begin(), quaternion.end(), o.quaternion);
  mesh_obstacle_list_t msg{};
  msg.num_obstacles = 1;
  msg.obstacles.push_back(o);
  return msg;
}

const bool kSendObstacle = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-obstacle", "add, move or remove one obstacle");
  auto c = std::make_shared<Common>();
  auto id = std::make_shared<std::string>();
  auto source = std::make_shared<std::string>();
  auto shape = std::make_shared<std::string>("box");
  auto size = std::make_shared<std::string>();
  auto mesh = std::make_shared<std::string>();
  auto scale = std::make_shared<std::string>("1,1,1");
  auto position = std::make_shared<std::string>("0,0,0");
  auto quaternion = std::make_shared<std::string>("1,0,0,0");
  auto remove = std::make_shared<bool>(false);
  auto replace_all = std::make_shared<bool>(false);
  auto goal_id = std::make_shared<int64_t>(-1);
  auto utime = std::make_shared<int64_t>(-1);
  c->add(sub, true);
  sub->add_option("--id", *id, "obstacle name")->required();
  sub->add_option("--source", *source,
                  "who sends it (obstacle ids are per source), e.g. perception (default: \"\")");
  sub->add_option("--utime", *utime,
                  "the update's time on the robot's clock, µs (default: the wall clock); the "
                  "daemon replans only from a state at most --max-state-age older");
  sub->add_option("--shape", *shape, "box, sphere, cylinder, capsule or mesh")
      ->check(CLI::IsMember({"box", "sphere", "cylinder", "capsule", "mesh"}));
  sub->add_option("--size", *size, "box: x,y,z; sphere: r; cylinder/capsule: r,length");
  sub->add_option("--mesh", *mesh,
                  "mesh: the file as the daemon's machine sees it (absolute, or relative to the "
                  "daemon's scene, then its data directories)");
  sub->add_option("--scale", *scale, "mesh: per-axis scale x,y,z (default 1,1,1)");
  sub->add_option("--position", *position, "centre (a mesh: its origin) x,y,z (m)");
  sub->add_option("--quaternion", *quaternion, "orientation w,x,y,z");
  sub->add_flag("--remove", *remove, "remove the obstacle instead");
  sub->add_flag("--replace-all", *replace_all,
                "this obstacle replaces all of its source's, other sources' are kept");
  sub->add_option("--goal-id", *goal_id, "with --wait: the goal whose replan to wait for");
  sub->callback([=] {
    const bool is_mesh = *shape == "mesh";
    if (is_mesh && !*remove && mesh->empty()) throw CommandFailure("--shape mesh needs --mesh");
    if (!is_mesh && !mesh->empty()) throw CommandFailure("--mesh needs --shape mesh");
    if (is_mesh && !size->empty()) throw CommandFailure("a mesh takes --scale, not --size");
    if (is_mesh && *replace_all) {
      throw CommandFailure("--replace-all is sent with box, sphere, cylinder and capsule obstacles");
    }
    if (c->wait_s > 0 && *goal_id < 0) throw CommandFailure("--wait needs --goal-id");
    const auto p = parse_number_list(*position, "--position", 3);
    const auto r = parse_number_list(*quaternion, "--quaternion", 4);
    const int64_t when = *utime >= 0 ? *utime : now_utime();
    obstacle_list_t msg{};
    mesh_obstacle_list_t mesh_msg{};
    if (is_mesh) {
      mesh_msg = mesh_obstacle_message(*id, *remove, *mesh, *scale, p, r);
      mesh_msg.utime = when;
      mesh_msg.source = *source;
    } else {
      obstacle_t o{};
      o.id = *id;
      o.action = *remove ? obstacle_t::REMOVE : obstacle_t::ADD_OR_MOVE;
      o.shape = *shape == "box"        ? obstacle_t::BOX
                : *shape == "sphere"   ? obstacle_t::SPHERE
                : *shape == "cylinder" ? obstacle_t::CYLINDER
                                       : obstacle_t::CAPSULE;
      if (!*remove) {
        auto s = parse_number_list(*size, "--size");
        if (s.empty() || s.size() > 3) throw CommandFailure("--size needs 1 to 3 numbers");
        std::copy(s.begin(), s.end(), o.size);
      }
      std::copy(p.begin(), p.end(), o.position);
      std::copy(r.begin(), r.end(), o.quaternion);
      msg.utime = when;
      msg.source = *source;
      msg.num_obstacles = 1;
      msg.obstacles.push_back(o);
      msg.replace_all = *replace_all;
    }
    std::optional<planning::Scene> scene = c->output_scene();
    // The obstacle as the plan file (--out) must hold it: converted as the daemon does.
    std::optional<std::pair<std::string, collision::Obstacle>> extra;
    if (!*remove && scene) {
      std::vector<messages::ObstacleUpdate> updates;
      const std::string anchor = std::filesystem::path(scene->source).parent_path().string();
      const messages::Check check = is_mesh
                                        ? messages::mesh_obstacles_from_message(mesh_msg, anchor,
                                                                                updates)
                                        : messages::obstacles_from_message(msg, updates);
      if (!check.ok) throw CommandFailure("send-obstacle: " + check.reason + " (nothing sent)");
      collision::Obstacle obstacle;
      obstacle.shape = updates[0].shape;
      obstacle.pose = updates[0].pose;
      extra.emplace(*id, obstacle);
    }
    lcm::LCM& lcm = open_lcm(c->url);
    PlanWaiter waiter(lcm, c->prefix + "_PLAN");
    if (is_mesh) {
      lcm.publish(c->prefix + "_OBSTACLES", &mesh_msg);
    } else {
      lcm.publish(c->prefix + "_OBSTACLES", &msg);
    }
    std::cout << "sent obstacle \"" << *id << "\""
              << (source->empty() ? "" : " from source \"" + *source + "\"")
              << (*replace_all ? " replacing its others" : "") << " on " << c->prefix
              << "_OBSTACLES (" << (is_mesh ? "mesh_obstacle_list_t" : "obstacle_list_t") << ")\n";
    if (int code = finish(waiter, *c, *goal_id, std::move(scene), extra); code != 0) {
      throw CommandFailure("", code);
    }
  });
});

const bool kSendPayload = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "send-payload", "attach a box payload to a link of the daemon's robot, or detach it");
  auto c = std::make_shared<Common>();
  auto frame = std::make_shared<std::string>();
  auto mass = std::make_shared<double>(-1);
  auto size = std::make_shared<std::string>();
  auto offset = std::make_shared<std::string>("0,0,0");
  auto detach = std::make_shared<bool>(false);
  auto robot = std::make_shared<std::string>();
  auto utime = std::make_shared<int64_t>(-1);
  c->add(sub, false);
  sub->add_option("--frame", *frame, "link or frame the box is fixed in");
  sub->add_option("--mass", *mass, "kg, uniform density")->check(CLI::NonNegativeNumber);
  sub->add_option("--size", *size, "full extents x,y,z in --frame (m)");
  sub->add_option("--offset", *offset, "box centre in --frame x,y,z (m, default 0,0,0)");
  sub->add_flag("--detach", *detach, "carry no payload from now on");
  sub->add_option("--robot", *robot, "robot name in the message (default: empty = any)");
  sub->add_option("--utime", *utime, "the change's time on the robot's clock, µs");
  sub->callback([=] {
    payload_t msg{};
    msg.utime = *utime >= 0 ? *utime : now_utime();
    msg.robot = *robot;
    if (*detach) {
      if (!frame->empty() || *mass >= 0 || !size->empty())
        throw CommandFailure("send-payload: --detach takes no --frame, --mass or --size");
      msg.action = payload_t::DETACH;
    } else {
      if (frame->empty() || *mass < 0 || size->empty())
        throw CommandFailure("send-payload needs --frame, --mass and --size (or --detach)");
      msg.action = payload_t::ATTACH;
      msg.frame = *frame;
      msg.mass_kg = *mass;
      const auto s = parse_number_list(*size, "--size", 3);
      const auto o = parse_number_list(*offset, "--offset", 3);
      std::copy(s.begin(), s.end(), msg.size);
      std::copy(o.begin(), o.end(), msg.offset);
    }
    open_lcm(c->url).publish(c->prefix + "_PAYLOAD", &msg);
    std::cout << "sent " << (*detach ? "detach" : "payload on '" + *frame + "'") << " on "
              << c->prefix << "_PAYLOAD (the daemon's next plans carry it; a refusal is on "
              << c->prefix << "_PLANNER_STATUS)\n";
  });
});

const bool kSendState = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-state", "publish a measured robot_state_t");
  auto c = std::make_shared<Common>();
  auto scene = std::make_shared<std::string>();
  auto q = std::make_shared<std::string>();
  auto qd = std::make_shared<std::string>();
  auto utime = std::make_shared<int64_t>(-1);
  c->add(sub, false);
  sub->add_option("--utime", *utime,
                  "measurement time on the robot's clock (µs) (default: the wall clock)");
  sub->add_option("--scene", *scene, "scene with the robot (for the joint names)")->required();
  sub->add_option("--q", *q, "joint positions, comma-separated")->required();
  sub->add_option("--qd", *qd, "joint velocities (default zeros)");
  sub->callback([=] {
    const auto s = planning::load_scene(*scene);
    const auto& model = *s.problem.model;
    robot_state_t msg;
    msg.utime = *utime >= 0 ? *utime : now_utime();
    msg.robot = model.name;
    msg.num_joints = model.nq();
    for (const auto& b : model.bodies) msg.joint_name.push_back(b.joint_name);
    msg.position = parse_number_list(*q, "--q", model.nq());
    msg.velocity = qd->empty() ? std::vector<double>(model.nq(), 0.0)
                               : parse_number_list(*qd, "--qd", model.nq());
    open_lcm(c->url).publish(c->prefix + "_STATE", &msg);
    std::cout << "sent state on " << c->prefix << "_STATE\n";
  });
});

// Robustness testing: publish arbitrary bytes on a channel, to see a daemon reject them.
const bool kSendRaw = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-raw", "publish raw bytes on a channel (for testing)");
  auto channel = std::make_shared<std::string>();
  auto text = std::make_shared<std::string>();
  auto url = std::make_shared<std::string>();
  sub->add_option("channel", *channel, "channel, e.g. IIWA_GOAL")->required();
  sub->add_option("--text", *text, "the bytes to send, as text")->required();
  sub->add_option("--lcm-url", *url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  sub->callback([=] {
    open_lcm(*url).publish(*channel, text->data(), static_cast<unsigned>(text->size()));
    std::cout << "sent " << text->size() << " bytes on " << *channel << "\n";
  });
});

// The obstacles a daemon received over LCM, replayed from a log in order: ids per source, a
// replace_all empties its source first (as kinographd applies them).
class LoggedObstacles {
 public:
  explicit LoggedObstacles(std::string mesh_anchor) : mesh_anchor_(std::move(mesh_anchor)) {}

  /// Applies one message of the obstacle channel; false (with `why`) when it is none of the
  /// obstacle list types or fails their checks.
  bool apply(const lcm::LogEvent& event, std::string& why) {
    std::vector<messages::ObstacleUpdate> updates;
    obstacle_list_t list;
    obstacle_list_v1_t v1;
    mesh_obstacle_list_t meshes;
    messages::Check check;
    if (lcmtypes::has_fingerprint<mesh_obstacle_list_t>(event.data, event.datalen)) {
      const auto decoded = lcmtypes::safe_decode(event.data, event.datalen, meshes);
      check = decoded.ok ? messages::mesh_obstacles_from_message(meshes, mesh_anchor_, updates)
                         : messages::Check::fail(decoded.reason);
    } else {
      const auto decoded = lcmtypes::safe_decode(event.data, event.datalen, list);
      if (!decoded.ok && lcmtypes::safe_decode(event.data, event.datalen, v1).ok) {
        list = messages::obstacle_list_from_v1(v1);
      } else if (!decoded.ok) {
        why = decoded.reason;
        return false;
      }
      check = messages::obstacles_from_message(list, updates);
      if (check.ok && list.replace_all) {
        std::erase_if(world_, [&](const auto& entry) { return entry.first.first == list.source; });
      }
    }
    if (!check.ok) {
      why = check.reason;
      return false;
    }
    for (messages::ObstacleUpdate& u : updates) {
      const messages::ObstacleKey key{u.source, u.id};
      if (u.remove) {
        world_.erase(key);
      } else {
        world_[key] = std::move(u);
      }
    }
    return true;
  }
  /// The obstacles now, each named by its id (and source, when it has one).
  std::vector<std::pair<std::string, collision::Obstacle>> now() const {
    std::vector<std::pair<std::string, collision::Obstacle>> out;
    for (const auto& [key, u] : world_) {
      collision::Obstacle o;
      o.shape = u.shape;
      o.pose = u.pose;
      out.emplace_back(key.first.empty() ? key.second : key.first + "/" + key.second, o);
    }
    return out;
  }

 private:
  std::string mesh_anchor_;
  std::map<messages::ObstacleKey, messages::ObstacleUpdate> world_;
};

const bool kLogPlans = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "log-plans",
      "write the plans in an LCM log as plan JSON files, with the obstacles received over LCM");
  auto log = std::make_shared<std::string>();
  auto channel = std::make_shared<std::string>();
  auto obstacles_channel = std::make_shared<std::string>();
  auto scene = std::make_shared<std::string>();
  auto out_dir = std::make_shared<std::string>(".");
  sub->add_option("log", *log, "LCM log file (lcm-logger)")->required();
  sub->add_option("--channel", *channel, "plan channel, e.g. IIWA_PLAN")->required();
  sub->add_option("--obstacles-channel", *obstacles_channel,
                  "the daemon's obstacle channel, whose updates each plan file carries "
                  "(default: --channel with _PLAN replaced by _OBSTACLES; \"none\" = ignore)");
  sub->add_option("--scene", *scene, "the daemon's scene (robot for the JSON)")->required();
  sub->add_option("--out-dir", *out_dir, "folder for plan_<goal>_<plan>.json");
  sub->callback([=] {
    planning::Scene s;
    try {
      s = planning::load_scene(*scene);
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
    std::string obstacle_channel = *obstacles_channel;
    const std::string plan_suffix = "_PLAN";
    if (obstacle_channel.empty() && channel->size() > plan_suffix.size() &&
        channel->compare(channel->size() - plan_suffix.size(), plan_suffix.size(), plan_suffix) ==
            0) {
      obstacle_channel = channel->substr(0, channel->size() - plan_suffix.size()) + "_OBSTACLES";
    }
    if (obstacle_channel == "none") obstacle_channel.clear();
    std::vector<std::string> joints;
    for (const auto& b : s.problem.model->bodies) joints.push_back(b.joint_name);
    lcm::LogFile file(*log, "r");
    if (!file.good()) throw CommandFailure("cannot read LCM log " + *log);
    // Every plan is checked against the scene's robot before any file is written, so a wrong
    // --scene writes nothing.
    struct Found {
      std::string path;
      planning::Plan plan;
      std::vector<std::pair<std::string, collision::Obstacle>> obstacles;  // received over LCM
    };
    std::vector<Found> plans;
    LoggedObstacles world(std::filesystem::path(s.source).parent_path().string());
    int rejected = 0, old = 0, obstacle_updates = 0, bad_updates = 0;
    // Prints a decoded plan of either version and keeps it when it has a trajectory.
    auto take = [&](const auto& msg) {
      std::cout << summarize(msg) << "\n";
      if (msg.num_steps == 0) return;
      if (msg.joint_name != joints) {
        throw CommandFailure("plan " + std::to_string(msg.plan_id) + " for goal " +
                             std::to_string(msg.goal_id) + " moves joints [" +
                             join_names(msg.joint_name) + "] but the robot of " + *scene +
                             " has [" + join_names(joints) +
                             "]; give the scene the daemon served (nothing written)");
      }
      plans.push_back({*out_dir + "/plan_" + std::to_string(msg.goal_id) + "_" +
                           std::to_string(msg.plan_id) + ".json",
                       messages::plan_from_message(msg), world.now()});
    };
    while (const lcm::LogEvent* event = file.readNextEvent()) {
      if (!obstacle_channel.empty() && event->channel == obstacle_channel) {
        std::string why;
        if (world.apply(*event, why)) {
          ++obstacle_updates;
        } else {
          std::cerr << "kinograph: " << obstacle_channel << " message at " << event->timestamp
                    << " us not applied: " << why << "\n";
          ++bad_updates;
        }
        continue;
      }
      if (event->channel != *channel) continue;
      // The fingerprint says which version of plan_t a message is (lcmtypes/README.md).
      plan_t msg;
      plan_v1_t v1;
      const auto current = lcmtypes::safe_decode(event->data, event->datalen, msg);
      if (current.ok) {
        take(msg);
      } else if (lcmtypes::safe_decode(event->data, event->datalen, v1).ok) {
        take(v1);
        ++old;
      } else {
        std::cerr << "kinograph: " << *channel << " message at " << event->timestamp
                  << " us is not a plan_t of version 2 or 1 (" << current.reason << "); skipped\n";
        ++rejected;
      }
    }
    std::filesystem::create_directories(*out_dir);
    for (const Found& f : plans) {
      planning::Scene with_lcm = s;
      for (const auto& [name, obstacle] : f.obstacles) add_obstacle(with_lcm, name, obstacle);
      write_plan_json(f.plan, with_lcm, f.path);
    }
    std::cout << plans.size() << " plans written to " << *out_dir;
    if (old) std::cout << ", " << old << " of version 1 (no clock)";
    if (rejected) std::cout << ", " << rejected << " messages that are not plans skipped";
    if (!obstacle_channel.empty()) {
      std::cout << "; " << obstacle_updates << " obstacle updates from " << obstacle_channel
                << " applied";
      if (bad_updates) std::cout << ", " << bad_updates << " not applied";
    }
    std::cout << "\n";
  });
});

}  // namespace
}  // namespace kinograph::tools
