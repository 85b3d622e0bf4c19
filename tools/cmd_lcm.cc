// LCM verbs of the CLI: talk to a running kinographd.
//   kinograph send-goal     --prefix IIWA (--q ... | --joint NAME=V ... | --frame F
//                           --position ... (--quaternion ... | --position-only)) [--utime US]
//   kinograph send-obstacle --prefix IIWA --id box --shape box --size ... --position ...
//                           [--source NAME [--replace-all]] [--utime US]
//   kinograph send-state    --prefix IIWA --scene S --q ... [--qd ...] [--utime US]
//   kinograph send-raw      CHANNEL --text BYTES
//   kinograph log-plans     LOG.lcmlog --channel IIWA_PLAN --scene S --out-dir DIR
// send-goal and send-obstacle can wait for the answering plan (--wait) and write it (--out).
// --utime stamps a message on the robot's clock (e.g. sim time) instead of the wall clock.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "kinograph/goal_t.hpp"
#include "kinograph/goal_v2_t.hpp"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/obstacle_list_t.hpp"
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
    if (extra) {
      scene->obstacle_names.push_back(extra->first);
      scene->problem.obstacles.push_back(extra->second);
      scene->problem.obstacles.back().id = static_cast<int>(scene->problem.obstacles.size()) - 1;
    }
    if (plan->num_steps == 0)
      throw CommandFailure("plan has no trajectory to write", kExitInvalidPlan);
    write_plan_json(messages::plan_from_message(*plan), *scene, c.out);
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

const bool kSendGoal = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "send-goal", "publish a goal to a kinographd (goal_t for --q, goal_v2_t otherwise)");
  auto c = std::make_shared<Common>();
  auto q = std::make_shared<std::string>();
  auto joints = std::make_shared<std::vector<std::string>>();
  auto frame = std::make_shared<std::string>();
  auto position = std::make_shared<std::string>();
  auto quaternion = std::make_shared<std::string>();
  auto position_only = std::make_shared<bool>(false);
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
  sub->add_option("--joint", *joints,
                  "joint goal by name, NAME=VALUE (rad), repeatable; joints not named are held "
                  "at their start");
  sub->add_option("--frame", *frame, "end-effector frame for a pose goal");
  sub->add_option("--position", *position, "pose goal position x,y,z (m)");
  sub->add_option("--quaternion", *quaternion,
                  "pose goal orientation w,x,y,z (required with --frame unless --position-only; "
                  "1,0,0,0 = the world's axes)");
  sub->add_flag("--position-only", *position_only,
                "pose goal: reach --position in any orientation");
  sub->add_option("--duration", *duration, "plan duration (s), 0 = the daemon's default");
  sub->add_option("--robot", *robot, "robot name in the message (default: empty = any)");
  sub->callback([=] {
    const bool pose = !frame->empty() || !position->empty() || !quaternion->empty();
    const int kinds = !q->empty() + !joints->empty() + pose;
    if (kinds > 1) {
      throw CommandFailure(
          "send-goal: give one goal: --q, --joint, or a pose goal (--frame, --position, "
          "--quaternion), not both");
    }
    if (kinds == 0) {
      throw CommandFailure(
          "send-goal needs --q, --joint, or --frame with --position and --quaternion");
    }
    if (*position_only && !pose) throw CommandFailure("--position-only is for pose goals");
    const int64_t id = *goal_id >= 0 ? *goal_id : now_utime();
    const int64_t when = *utime >= 0 ? *utime : now_utime();
    // Every joint in URDF order is what the first goal type says; names need version 2.
    goal_t v1{};
    goal_v2_t v2{};
    if (!q->empty()) {
      v1.utime = when;
      v1.goal_id = id;
      v1.robot = *robot;
      v1.duration_s = *duration;
      v1.ee_quaternion[0] = 1;
      v1.kind = goal_t::KIND_JOINT_CONFIGURATION;
      v1.joint_position = parse_number_list(*q, "--q");
      v1.num_joints = static_cast<int32_t>(v1.joint_position.size());
    } else {
      v2.utime = when;
      v2.goal_id = id;
      v2.robot = *robot;
      v2.duration_s = *duration;
      v2.ee_quaternion[0] = 1;
      if (!joints->empty()) {
        v2.kind = goal_v2_t::KIND_JOINT_CONFIGURATION;
        for (const std::string& item : *joints) {
          const auto [name, value] = parse_named_joint(item);
          v2.joint_name.push_back(name);
          v2.joint_position.push_back(value);
        }
        v2.num_joints = static_cast<int32_t>(v2.joint_name.size());
      } else {
        if (frame->empty() || position->empty() || (quaternion->empty() && !*position_only)) {
          throw CommandFailure(
              "send-goal: a pose goal needs --frame, --position and --quaternion "
              "(--quaternion 1,0,0,0 keeps the world's axes; --position-only ignores it)");
        }
        if (*position_only && !quaternion->empty()) {
          throw CommandFailure("send-goal: --position-only ignores the orientation: drop "
                               "--quaternion");
        }
        v2.kind = goal_v2_t::KIND_END_EFFECTOR_POSE;
        v2.ee_frame = *frame;
        v2.position_only = *position_only;
        auto p = parse_number_list(*position, "--position", 3);
        std::copy(p.begin(), p.end(), v2.ee_position);
        if (!quaternion->empty()) {
          auto r = parse_number_list(*quaternion, "--quaternion", 4);
          std::copy(r.begin(), r.end(), v2.ee_quaternion);
        }
      }
    }
    std::optional<planning::Scene> scene = c->output_scene();
    lcm::LCM& lcm = open_lcm(c->url);
    PlanWaiter waiter(lcm, c->prefix + "_PLAN");
    if (!q->empty()) {
      lcm.publish(c->prefix + "_GOAL", &v1);
    } else {
      lcm.publish(c->prefix + "_GOAL", &v2);
    }
    std::cout << "sent goal " << id << " on " << c->prefix << "_GOAL ("
              << (q->empty() ? "goal_v2_t" : "goal_t") << ")\n";
    if (int code = finish(waiter, *c, id, std::move(scene)); code != 0) {
      throw CommandFailure("", code);
    }
  });
});

const bool kSendObstacle = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-obstacle", "add, move or remove one obstacle");
  auto c = std::make_shared<Common>();
  auto id = std::make_shared<std::string>();
  auto shape = std::make_shared<std::string>("box");
  auto size = std::make_shared<std::string>();
  auto position = std::make_shared<std::string>("0,0,0");
  auto quaternion = std::make_shared<std::string>("1,0,0,0");
  auto remove = std::make_shared<bool>(false);
  auto source = std::make_shared<std::string>();
  auto replace_all = std::make_shared<bool>(false);
  auto goal_id = std::make_shared<int64_t>(-1);
  auto utime = std::make_shared<int64_t>(-1);
  c->add(sub, true);
  sub->add_option("--id", *id, "obstacle name")->required();
  sub->add_option("--utime", *utime,
                  "the update's time on the robot's clock, µs (default: the wall clock); the "
                  "daemon replans only from a state at most --max-state-age older");
  sub->add_option("--shape", *shape, "box, sphere, cylinder or capsule")
      ->check(CLI::IsMember({"box", "sphere", "cylinder", "capsule"}));
  sub->add_option("--size", *size, "box: x,y,z; sphere: r; cylinder/capsule: r,length");
  sub->add_option("--position", *position, "centre x,y,z (m)");
  sub->add_option("--quaternion", *quaternion, "orientation w,x,y,z");
  sub->add_flag("--remove", *remove, "remove the obstacle instead");
  sub->add_option("--source", *source,
                  "who sends it (obstacle_list_t.source, default none): ids are per source");
  sub->add_flag("--replace-all", *replace_all,
                "this obstacle replaces all of its source's, other sources' are kept");
  sub->add_option("--goal-id", *goal_id, "with --wait: the goal whose replan to wait for");
  sub->callback([=] {
    obstacle_t o;
    o.id = *id;
    o.action = *remove ? obstacle_t::REMOVE : obstacle_t::ADD_OR_MOVE;
    o.shape = *shape == "box"        ? obstacle_t::BOX
              : *shape == "sphere"   ? obstacle_t::SPHERE
              : *shape == "cylinder" ? obstacle_t::CYLINDER
                                     : obstacle_t::CAPSULE;
    std::fill(std::begin(o.size), std::end(o.size), 0.0);
    if (!*remove) {
      auto s = parse_number_list(*size, "--size");
      if (s.empty() || s.size() > 3) throw CommandFailure("--size needs 1 to 3 numbers");
      std::copy(s.begin(), s.end(), o.size);
    }
    auto p = parse_number_list(*position, "--position", 3);
    auto r = parse_number_list(*quaternion, "--quaternion", 4);
    std::copy(p.begin(), p.end(), o.position);
    std::copy(r.begin(), r.end(), o.quaternion);
    obstacle_list_t msg;
    msg.utime = *utime >= 0 ? *utime : now_utime();
    msg.source = *source;
    msg.num_obstacles = 1;
    msg.obstacles.push_back(o);
    msg.replace_all = *replace_all;
    if (c->wait_s > 0 && *goal_id < 0) throw CommandFailure("--wait needs --goal-id");
    std::optional<planning::Scene> scene = c->output_scene();
    lcm::LCM& lcm = open_lcm(c->url);
    PlanWaiter waiter(lcm, c->prefix + "_PLAN");
    lcm.publish(c->prefix + "_OBSTACLES", &msg);
    std::cout << "sent obstacle \"" << o.id << "\""
              << (source->empty() ? "" : " from source \"" + *source + "\"")
              << (*replace_all ? " replacing its others" : "") << " on " << c->prefix
              << "_OBSTACLES\n";
    std::optional<std::pair<std::string, collision::Obstacle>> extra;
    if (!*remove) {
      std::vector<messages::ObstacleUpdate> updates;
      if (messages::obstacles_from_message(msg, updates).ok) {
        collision::Obstacle obstacle;
        obstacle.shape = updates[0].shape;
        obstacle.pose = updates[0].pose;
        extra.emplace(o.id, obstacle);
      }
    }
    if (int code = finish(waiter, *c, *goal_id, std::move(scene), extra); code != 0) {
      throw CommandFailure("", code);
    }
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

const bool kLogPlans = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("log-plans", "write the plans in an LCM log as plan JSON files");
  auto log = std::make_shared<std::string>();
  auto channel = std::make_shared<std::string>();
  auto scene = std::make_shared<std::string>();
  auto out_dir = std::make_shared<std::string>(".");
  sub->add_option("log", *log, "LCM log file (lcm-logger)")->required();
  sub->add_option("--channel", *channel, "plan channel, e.g. IIWA_PLAN")->required();
  sub->add_option("--scene", *scene, "the daemon's scene (robot for the JSON)")->required();
  sub->add_option("--out-dir", *out_dir, "folder for plan_<goal>_<plan>.json");
  sub->callback([=] {
    planning::Scene s;
    try {
      s = planning::load_scene(*scene);
    } catch (const std::exception& e) {
      throw CommandFailure(e.what());
    }
    std::vector<std::string> joints;
    for (const auto& b : s.problem.model->bodies) joints.push_back(b.joint_name);
    lcm::LogFile file(*log, "r");
    if (!file.good()) throw CommandFailure("cannot read LCM log " + *log);
    // Every plan is checked against the scene's robot before any file is written, so a wrong
    // --scene writes nothing.
    struct Found {
      std::string path;
      planning::Plan plan;
    };
    std::vector<Found> plans;
    int rejected = 0, old = 0;
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
                       messages::plan_from_message(msg)});
    };
    while (const lcm::LogEvent* event = file.readNextEvent()) {
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
    for (const Found& f : plans) write_plan_json(f.plan, s, f.path);
    std::cout << plans.size() << " plans written to " << *out_dir;
    if (old) std::cout << ", " << old << " of version 1 (no clock)";
    if (rejected) std::cout << ", " << rejected << " messages that are not plans skipped";
    std::cout << "\n";
  });
});

}  // namespace
}  // namespace kinograph::tools
