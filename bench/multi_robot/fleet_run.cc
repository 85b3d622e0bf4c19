#include "bench/multi_robot/fleet_run.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <net/if.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "kinograph/cell/cell.h"
#include "kinograph/execution/plan_schedule.h"
#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/goal_t.hpp"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/formulation/planning_graph.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/trajectory_sampler.h"
#include "kinograph/planning/validate.h"
#include "lcmtypes/safe_decode.h"

namespace kinograph::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

int64_t wall_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

double load_average() {
  double load[1] = {std::nan("")};
  return getloadavg(load, 1) == 1 ? load[0] : std::nan("");
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The last `lines` lines of a file, for a failure's reason.
std::string tail(const std::string& path, int lines) {
  std::ifstream in(path);
  std::vector<std::string> all;
  for (std::string line; std::getline(in, line);) all.push_back(line);
  std::string out;
  for (std::size_t i = all.size() > static_cast<std::size_t>(lines) ? all.size() - lines : 0;
       i < all.size(); ++i) {
    out += all[i] + "\n";
  }
  return out;
}

// One scene file per robot beside the cell: the cell's shared keys (every top-level key but
// `robots` and `name`) with the robot's own entry, as a cell composes its robots' scenes; beside
// the cell, relative paths resolve as they do in it. Each is read back and compared with the
// cell's robot, so the daemons plan exactly the centralized problem's arms.
std::vector<std::string> write_scenes(const std::string& cell_path, const cell::Cell& c) {
  const YAML::Node root = YAML::LoadFile(cell_path);
  const fs::path dir = fs::path(cell_path).parent_path();
  std::vector<std::string> paths;
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    const std::string& name = c.robots[i].name;
    YAML::Node scene(YAML::NodeType::Map);
    scene["name"] = c.name + "." + name;
    for (const auto& key : root) {
      const std::string k = key.first.Scalar();
      if (k != "robots" && k != "name") scene[k] = key.second;
    }
    for (const auto& key : root["robots"][i]) {
      if (key.first.Scalar() != "name") scene[key.first.Scalar()] = key.second;
    }
    YAML::Emitter out;
    out << scene;
    const std::string path =
        (dir / (fs::path(cell_path).stem().string() + "." + name + ".yaml")).string();
    std::ofstream(path) << "# Robot '" << name << "' of the cell " << cell_path
                        << ", for its own kinographd (bench/multi_robot).\n"
                        << out.c_str() << "\n";
    const planning::Problem& want = c.robots[i].scene.problem;
    const planning::Problem got = planning::load_scene(path).problem;
    if (got.start_q != want.start_q || got.goal.q != want.goal.q || got.steps != want.steps ||
        got.horizon != want.horizon || got.obstacles.size() != want.obstacles.size()) {
      throw std::runtime_error("the scene " + path + " written for robot '" + name +
                               "' does not read back as the cell's robot");
    }
    paths.push_back(path);
  }
  return paths;
}

// The daemons this run started, stopped (by their PIDs only) when it ends however it ends.
class Daemons {
 public:
  ~Daemons() { stop(); }

  // Starts `argv` with stdout and stderr to `log`; it is killed if this process dies.
  void start(const std::vector<std::string>& argv, const std::string& log) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) throw std::runtime_error("cannot write " + log);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) {
      close(fd);
      throw std::runtime_error("fork failed");
    }
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(127);
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
      execv(args[0], args.data());
      _exit(127);
    }
    close(fd);
    pids_.push_back(pid);
    logs_.push_back(log);
  }

  // The log of a daemon that has exited, or empty while all run.
  std::string exited() {
    for (std::size_t i = 0; i < pids_.size(); ++i) {
      int status = 0;
      if (pids_[i] > 0 && waitpid(pids_[i], &status, WNOHANG) == pids_[i]) {
        pids_[i] = -1;
        return logs_[i];
      }
    }
    return "";
  }

  // SIGTERM to each, waited for (10 s, then SIGKILL); their CPU time in seconds.
  double stop() {
    double cpu = 0;
    for (pid_t& pid : pids_) {
      if (pid <= 0) continue;
      kill(pid, SIGTERM);
      const auto deadline = Clock::now() + std::chrono::seconds(10);
      int status = 0;
      rusage usage{};
      pid_t done = 0;
      while ((done = wait4(pid, &status, WNOHANG, &usage)) == 0 && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      if (done == 0) {
        kill(pid, SIGKILL);
        done = wait4(pid, &status, 0, &usage);
      }
      if (done == pid) {
        cpu += static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
               1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
      }
      pid = -1;
    }
    return cpu;
  }

 private:
  std::vector<pid_t> pids_;
  std::vector<std::string> logs_;
};

// What the bench knows of one arm's daemon, from its channels.
struct Arm {
  std::string name, prefix, scene_path, log;
  planning::Scene scene;
  int64_t goal_utime = -1;
  std::map<int64_t, plan_t> plans;  // valid plans answering our goal, by id
  std::optional<plan_t> current;    // the latest of them to arrive
  Clock::time_point current_arrival;
  std::string last_failure;  // status message of its latest failed answer, if the latest failed
  int plan_messages = 0;
  std::optional<planner_status_t> heartbeat;
};

// The fleet as heard on LCM, with every message on the arms' channels counted by kind.
struct Fleet {
  std::vector<Arm> arms;
  bool counting = false;
  std::map<std::string, int> messages;  // by channel suffix: PLAN, PLANNER_STATUS, ...
  bool plans_changed = false;
  Clock::time_point last_plan = Clock::now();

  Arm* arm_of(const std::string& channel, std::string& suffix) {
    for (Arm& a : arms) {
      if (channel.rfind(a.prefix + "_", 0) == 0) {
        suffix = channel.substr(a.prefix.size() + 1);
        return &a;
      }
    }
    return nullptr;
  }

  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    std::string suffix;
    Arm* arm = arm_of(channel, suffix);
    if (arm == nullptr) return;
    if (counting) ++messages[suffix];
    const int size = static_cast<int>(rbuf->data_size);
    if (suffix == "PLAN" || suffix == "PLAN_CURRENT") {
      plan_t msg;
      if (!lcmtypes::safe_decode(rbuf->data, size, msg).ok) return;
      last_plan = Clock::now();
      if (suffix == "PLAN") ++arm->plan_messages;
      if (msg.status == plan_t::SUCCESS && msg.valid) {
        if (arm->current && arm->current->plan_id == msg.plan_id) return;  // a resend
        arm->plans[msg.plan_id] = msg;
        arm->current = msg;
        arm->current_arrival = last_plan;
        arm->last_failure.clear();
        plans_changed = true;
      } else if (suffix == "PLAN") {
        arm->last_failure = msg.status_message.empty() ? "not valid" : msg.status_message;
      }
    } else if (suffix == "PLANNER_STATUS") {
      planner_status_t msg;
      if (lcmtypes::safe_decode(rbuf->data, size, msg).ok) arm->heartbeat = msg;
    }
  }

  // Why the fleet has not settled under the coordination rule, or empty: every daemon idle with
  // a valid plan of our goal that its heartbeat names as current, planned around the current
  // plan of every higher-priority arm (earlier goal utime: lower index here).
  std::string unsettled() const {
    for (const Arm& a : arms) {
      if (!a.heartbeat) return a.name + ": no heartbeat";
      const planner_status_t& hb = *a.heartbeat;
      if (hb.state != planner_status_t::IDLE) return a.name + ": planning";
      if (hb.goal_utime != a.goal_utime || hb.valid_plan_id < 0) {
        return a.name + ": no valid plan of its goal" +
               (a.last_failure.empty() ? "" : " (" + a.last_failure + ")");
      }
      if (a.plans.count(hb.valid_plan_id) == 0) {
        return a.name + ": current plan " + std::to_string(hb.valid_plan_id) + " not received";
      }
    }
    for (std::size_t i = 0; i < arms.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        const std::string followed =
            fmt::format("{}: plan {}, followed", arms[j].name, arms[j].heartbeat->valid_plan_id);
        if (arms[i].heartbeat->neighbours.find(followed) == std::string::npos) {
          return fmt::format("{} does not follow {}'s current plan ({})", arms[i].name,
                             arms[j].name, arms[i].heartbeat->neighbours);
        }
      }
    }
    return "";
  }

  bool all_idle() const {
    for (const Arm& a : arms) {
      if (!a.heartbeat || a.heartbeat->state != planner_status_t::IDLE) return false;
    }
    return true;
  }
};

// The arms' motions on the common clock (seconds from `origin_utime`): each moves along the valid
// plans its daemon published, each in force from its start_utime until a later one starts, as a
// daemon without states has its robot move (docs/multi_robot.md); checked together at and
// between the knots. `memo` keeps the windows already checked.
fleet::JointClearance together(const std::vector<Arm>& arms, int64_t origin_utime,
                               fleet::HistoryMemo& memo) {
  std::vector<fleet::RobotHistory> robots;
  for (const Arm& a : arms) {
    fleet::RobotHistory h{a.name, a.scene.problem.model, {}};
    for (const auto& [id, msg] : a.plans) {
      h.plans.push_back({messages::plan_from_message(msg),
                         static_cast<double>(msg.start_utime - origin_utime) * 1e-6});
    }
    robots.push_back(std::move(h));
  }
  return fleet::history_clearance(robots, {}, &memo);
}

// The id of the arm's plan in force at `utime` (the latest started by then; its first before
// any), and whether it is the arm's current plan.
std::string in_force_at(const Arm& arm, int64_t utime) {
  int64_t id = arm.plans.begin()->first;
  for (const auto& [plan_id, msg] : arm.plans) {
    if (msg.start_utime <= utime) id = plan_id;
  }
  const bool current = arm.current && arm.current->plan_id == id;
  return fmt::format("{} on its plan {}{}", arm.name, id, current ? " (its current one)" : "");
}

// How far (rad, rad/s: the larger) the arm's plan `id` starts from where the arm is when it
// starts: along its plans before it, or at its scene's start before any.
double start_gap(const Arm& arm, int64_t id) {
  const plan_t& msg = arm.plans.at(id);
  const planning::Plan plan = messages::plan_from_message(msg);
  Eigen::VectorXd q = arm.scene.problem.start_q, qd = Eigen::VectorXd::Zero(q.size());
  // The plan in force when it starts: the latest before it started by then.
  for (auto it = arm.plans.begin(); it != arm.plans.end() && it->first < id; ++it) {
    if (it->second.start_utime > msg.start_utime) continue;
    execution::TimedPlan before{it->first, it->second.start_utime, it->second.start_utime, -1,
                                messages::plan_from_message(it->second)};
    planning::TrajectorySampler sampler(*arm.scene.problem.model, before.plan);
    const execution::Setpoint at = execution::sample_at(before, sampler, msg.start_utime);
    q = at.q;
    qd = at.qd;
  }
  return std::max((plan.q.row(0).transpose() - q).cwiseAbs().maxCoeff(),
                  (plan.qd.row(0).transpose() - qd).cwiseAbs().maxCoeff());
}

// The arm's scene with its start where `plan` starts: a replan from the motion under way is a
// plan of that problem.
planning::Problem from_its_start(const Arm& arm, const planning::Plan& plan) {
  planning::Problem problem = arm.scene.problem;
  problem.start_q = plan.q.row(0).transpose();
  problem.start_qd = plan.qd.row(0).transpose();
  return problem;
}

goal_t goal_message(const Arm& arm) {
  goal_t g{};
  g.utime = arm.goal_utime;
  g.goal_id = 1;
  g.robot = arm.prefix;
  g.kind = goal_t::KIND_JOINT_CONFIGURATION;
  const Eigen::VectorXd& q = arm.scene.problem.goal.q;
  g.joint_position.assign(q.data(), q.data() + q.size());
  g.num_joints = static_cast<int32_t>(q.size());
  g.ee_quaternion[0] = 1;
  g.duration_s = 0;  // the scene's horizon
  return g;
}

}  // namespace

double plan_objective(const planning::Problem& problem, const planning::Plan& plan) {
  const planning::Trajectory trajectory{plan.q, plan.qd, plan.qdd};
  const planning::PlanningGraph pg = planning::build_graph(problem, trajectory);
  return planning::soft_cost(pg.entries, pg.values);
}

void require_multicast(const std::string& url) {
  const std::string how =
      "run the distributed benchmark as root in a private network namespace with multicast "
      "routed on the loopback: unshare -n sh -c \"ip link set lo up && ip link set lo multicast "
      "on && ip route add 224.0.0.0/4 dev lo && multi_robot_bench ...\"";
  // A namespace with an interface besides the loopback is shared: the fleet's multicast would
  // mix with other programs' LCM traffic (and other daemons on the same channels).
  if (struct if_nameindex* interfaces = if_nameindex(); interfaces != nullptr) {
    std::string others;
    for (const struct if_nameindex* i = interfaces; i->if_index != 0; ++i) {
      if (std::string(i->if_name) != "lo")
        others += std::string(others.empty() ? "" : ", ") + i->if_name;
    }
    if_freenameindex(interfaces);
    if (!others.empty()) {
      throw std::runtime_error("the network namespace has interfaces besides the loopback (" +
                               others + "): " + how);
    }
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) throw std::runtime_error("LCM does not start on " + url + ": " + how);
  bool heard = false;
  auto* sub = lcm.subscribeFunction(
      "MULTI_ROBOT_BENCH_SELF_TEST",
      +[](const lcm::ReceiveBuffer*, const std::string&, bool* h) { *h = true; }, &heard);
  const char byte = 0;
  if (lcm.publish("MULTI_ROBOT_BENCH_SELF_TEST", &byte, 1) != 0) {
    throw std::runtime_error("cannot publish on " + url + " (multicast not routed?): " + how);
  }
  const auto deadline = Clock::now() + std::chrono::seconds(1);
  while (!heard && Clock::now() < deadline) lcm.handleTimeout(50);
  lcm.unsubscribe(sub);
  if (!heard) {
    throw std::runtime_error("a message published on " + url + " did not come back: " + how);
  }
}

nlohmann::json run_fleet(const std::string& cell_path, const FleetRunOptions& o) {
  const cell::Cell c = cell::load_cell(cell_path);
  const std::vector<std::string> scenes = write_scenes(cell_path, c);
  const std::string stem = fs::path(cell_path).stem().string();
  const std::string work =
      o.work_dir.empty() ? fs::path(cell_path).parent_path().string() : o.work_dir;
  Fleet fleet;
  for (std::size_t i = 0; i < c.robots.size(); ++i) {
    Arm a;
    a.name = c.robots[i].name;
    a.prefix = upper(a.name);
    a.scene_path = scenes[i];
    a.scene = planning::load_scene(scenes[i]);
    a.log = (fs::path(work) / (stem + "." + a.name + ".log")).string();
    fleet.arms.push_back(std::move(a));
  }
  nlohmann::json result;
  result["load1"] = load_average();
  lcm::LCM lcm(o.lcm_url);
  if (!lcm.good()) throw std::runtime_error("LCM does not start on " + o.lcm_url);
  lcm.subscribe(".*", &Fleet::on_message, &fleet)->setQueueCapacity(100000);

  Daemons daemons;
  for (const Arm& a : fleet.arms) {
    std::vector<std::string> argv = {
        o.kinographd, a.scene_path, "--prefix",        a.prefix,
        "--lcm-url",  o.lcm_url,    "--status-period", fmt::format("{}", o.status_period_s)};
    for (const Arm& n : fleet.arms) {
      if (&n != &a) argv.insert(argv.end(), {"--neighbour", n.name + "=" + n.scene_path});
    }
    daemons.start(argv, a.log);
  }
  const auto fail = [&](const std::string& why) {
    result["success"] = false;
    result["settled"] = false;
    result["reason"] = why;
    result["daemons_cpu_s"] = daemons.stop();
    return result;
  };
  // Started when every daemon's heartbeat has heard every neighbour.
  const auto startup_deadline = Clock::now() + std::chrono::duration<double>(o.startup_timeout_s);
  for (;;) {
    bool ready = true;
    for (const Arm& a : fleet.arms) {
      ready = ready && a.heartbeat &&
              a.heartbeat->neighbours.find("not heard yet") == std::string::npos;
    }
    if (ready) break;
    if (const std::string log = daemons.exited(); !log.empty()) {
      return fail("a daemon exited at its start: " + tail(log, 5));
    }
    if (Clock::now() > startup_deadline) {
      return fail(
          fmt::format("the daemons did not hear each other within {} s", o.startup_timeout_s));
    }
    lcm.handleTimeout(20);
  }

  // The goals, in priority order: an earlier utime outranks (docs/multi_robot.md).
  const int64_t utime0 = wall_utime();
  for (std::size_t i = 0; i < fleet.arms.size(); ++i) {
    fleet.arms[i].goal_utime = utime0 + static_cast<int64_t>(i);
  }
  fleet.counting = true;
  const auto t0 = Clock::now();
  for (const Arm& a : fleet.arms) {
    const goal_t g = goal_message(a);
    lcm.publish(a.prefix + "_GOAL", &g);
  }
  fleet.last_plan = t0;
  const auto deadline = t0 + std::chrono::duration<double>(o.timeout_s);
  std::optional<double> first_clear;
  fleet::HistoryMemo memo;
  std::string why;
  for (;;) {
    // Nothing left to handle: the view of the fleet is current. While the bench checks plans it
    // does not listen, and what came meanwhile waits in the socket: until that is handled, the
    // latest heartbeats handled may be older than plans already sent, so neither settling nor
    // quiet is judged then.
    const bool caught_up = lcm.handleTimeout(20) == 0;
    if (fleet.plans_changed && !first_clear) {
      fleet.plans_changed = false;
      bool all = true;
      Clock::time_point last = t0;
      for (const Arm& a : fleet.arms) {
        all = all && a.current;
        if (a.current) last = std::max(last, a.current_arrival);
      }
      // The moment the last of these plans arrived: when the fleet first held them all.
      if (all && together(fleet.arms, utime0, memo).clear()) {
        first_clear = seconds_between(t0, last);
      }
    }
    why = fleet.unsettled();
    if (why.empty() && caught_up) break;
    if (const std::string log = daemons.exited(); !log.empty()) {
      why = "a daemon exited: " + tail(log, 5);
      break;
    }
    const auto now = Clock::now();
    if (now > deadline) {
      why = fmt::format("not settled within {} s: {}", o.timeout_s, why);
      break;
    }
    if (caught_up && fleet.all_idle() && seconds_between(fleet.last_plan, now) > o.quiet_s) {
      why = fmt::format("no daemon planning and no plan for {} s, not settled: {}", o.quiet_s, why);
      break;
    }
  }
  const auto t_end = Clock::now();
  fleet.counting = false;
  const bool settled = why.empty();
  result["settled"] = settled;
  result["time_to_mutually_clear_s"] = first_clear ? nlohmann::json(*first_clear) : nullptr;
  result["time_to_settled_s"] = settled ? nlohmann::json(seconds_between(t0, t_end)) : nullptr;
  int messages = 0;
  for (const auto& [kind, count] : fleet.messages) messages += count;
  result["messages"] = messages;
  result["messages_by_kind"] = fleet.messages;

  int replans = 0, neighbour_replans = 0;
  double objective = 0;
  bool valid = settled;
  for (const Arm& a : fleet.arms) {
    nlohmann::json arm;
    arm["name"] = a.name;
    arm["plans_received"] = a.plan_messages;
    if (!a.last_failure.empty()) arm["last_failure"] = a.last_failure;
    // Its latest answer was a valid plan (a failed one leaves the daemon on its older plan).
    arm["holds_valid_plan"] = a.current.has_value() && a.last_failure.empty();
    if (a.heartbeat) {
      replans += std::max(0, a.heartbeat->num_plans - 1);
      neighbour_replans += a.heartbeat->num_neighbour_replans;
      arm["plans"] = a.heartbeat->num_plans;
      arm["neighbour_replans"] = a.heartbeat->num_neighbour_replans;
      arm["neighbours"] = a.heartbeat->neighbours;
    }
    if (settled) {
      const plan_t& msg = a.plans.at(a.heartbeat->valid_plan_id);
      const planning::Plan plan = messages::plan_from_message(msg);
      const planning::Problem problem = from_its_start(a, plan);
      const planning::Validation v = planning::validate(problem, plan);
      const double own = plan_objective(problem, plan);
      const double gap = start_gap(a, msg.plan_id);
      objective += own;
      arm["plan_id"] = msg.plan_id;
      arm["method"] = msg.method;
      arm["objective"] = own;
      arm["valid"] = v.valid;
      arm["start_gap"] = gap;
      if (!v.valid) {
        valid = false;
        if (why.empty()) why = a.name + "'s plan does not validate: " + v.failures.front();
      }
      // A replan continues the motion under way (the validator's start tolerance).
      if (gap > 1e-6) {
        valid = false;
        if (why.empty()) {
          why = fmt::format("{}'s plan {} starts {} away from where its plans had it", a.name,
                            msg.plan_id, gap);
        }
      }
    }
    result["arms"].push_back(arm);
  }
  result["replans"] = replans;
  result["neighbour_replans"] = neighbour_replans;
  if (settled) {
    const fleet::JointClearance jc = together(fleet.arms, utime0, memo);
    result["min_clearance"] = jc.min_distance;
    result["objective"] = objective;
    if (!jc.clear()) {
      valid = false;
      if (why.empty()) {
        // Which plans the two arms were moving along then: an older one is a yielding window.
        const int64_t at = utime0 + std::llround(jc.t * 1e6);
        std::string on;
        for (const Arm& a : fleet.arms) {
          if (a.name == jc.robot_a || a.name == jc.robot_b) {
            on += (on.empty() ? "" : ", ") + in_force_at(a, at);
          }
        }
        why = "the settled plans are not clear: " + fleet::describe(jc) + " (" + on + ")";
      }
    }
  }
  result["success"] = valid;
  if (!valid) result["reason"] = why;
  result["daemons_cpu_s"] = daemons.stop();
  return result;
}

}  // namespace kinograph::bench
