// fleet_probe: the observer of the multi-robot integration tests. It only listens, and waits on
// events with a bound, never on fixed sleeps.
//   fleet_probe settle --url URL --robot PREFIX=SCENE ... --out-dir DIR [--newer PREFIX=ID]
//       [--timeout S]
//   waits until the fleet has settled under the coordination rule: every robot idle with a valid
//   plan that its heartbeat names as current, planned around the current plan of every
//   higher-priority robot (its heartbeat says "name: plan N, followed", name = PREFIX
//   lower-cased), and with --newer a current plan id above ID. Then writes each robot's current
//   plan as DIR/<prefix>.json (with start_utime and plan_id; a file of an earlier run with the
//   current plan's id is kept) and prints per robot its plans and replans.
//   fleet_probe heartbeat --url URL --prefix PREFIX (--contains TEXT | --message TEXT)
//       [--steady K] [--timeout S]
//   waits for a heartbeat of PREFIX whose neighbours field (--contains) or message (--message)
//   contains TEXT, and prints that field; with --steady, then for K more heartbeats of PREFIX,
//   and fails when its count of published plans changes meanwhile (a robot replanning).
// Prints "ready" once subscribed.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "kinograph/lcm/message_convert.h"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/io/scene.h"
#include "lcmtypes/safe_decode.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Robot {
  std::string prefix, name, scene;
  std::map<int64_t, kinograph::plan_t> plans;  // SUCCESS plans by id
  int received = 0;                            // plan_t messages, any status
  std::optional<kinograph::planner_status_t> heartbeat;
  int64_t newer_than = -1;
  int64_t kept_plan_id = -1;  // plan_id of the plan file an earlier run left in the out dir
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::pair<std::string, std::string> split(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("expected A=B, got " + text);
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::tuple<int64_t, std::string> key(const Robot& r) {
  const int64_t g = r.heartbeat->goal_utime;
  return {g < 0 ? std::numeric_limits<int64_t>::max() : g, r.prefix};
}

// The "plan_id" of the plan file `path`, -1 when there is none.
int64_t kept_plan_id(const std::string& path) {
  std::ifstream in(path);
  if (!in) return -1;
  const nlohmann::json json = nlohmann::json::parse(in, nullptr, false);
  return json.is_object() && json.contains("plan_id") ? json["plan_id"].get<int64_t>() : -1;
}

// Why the fleet has not settled yet, or empty.
std::string unsettled(const std::vector<Robot>& robots) {
  for (const Robot& r : robots) {
    if (!r.heartbeat) return r.prefix + ": no heartbeat";
    const auto& hb = *r.heartbeat;
    if (hb.state != kinograph::planner_status_t::IDLE) return r.prefix + ": planning";
    if (hb.valid_plan_id < 0 ||
        (r.plans.count(hb.valid_plan_id) == 0 && r.kept_plan_id != hb.valid_plan_id)) {
      return r.prefix + ": current plan " + std::to_string(hb.valid_plan_id) + " not received";
    }
    if (hb.valid_plan_id <= r.newer_than) return r.prefix + ": no plan newer than asked";
  }
  for (const Robot& r : robots) {
    for (const Robot& n : robots) {
      if (&n == &r || !(key(n) < key(r))) continue;
      const std::string expected =
          n.name + ": plan " + std::to_string(n.heartbeat->valid_plan_id) + ", followed";
      if (r.heartbeat->neighbours.find(expected) == std::string::npos) {
        return r.prefix + " does not follow " + n.prefix + "'s current plan (" +
               r.heartbeat->neighbours + ")";
      }
    }
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fleet_probe: waits for a fleet of kinographd daemons to settle"};
  app.require_subcommand(1);
  std::string url, out_dir = ".";
  std::vector<std::string> robot_args, newer_args;
  double timeout_s = 120;
  CLI::App* settle = app.add_subcommand("settle", "wait until the fleet settles");
  settle->add_option("--url", url)->required();
  settle->add_option("--robot", robot_args, "PREFIX=SCENE")->required();
  settle->add_option("--newer", newer_args, "PREFIX=ID: its current plan must be above ID");
  settle->add_option("--out-dir", out_dir);
  settle->add_option("--timeout", timeout_s);
  std::string prefix, contains, message;
  int steady = 0;
  CLI::App* beat = app.add_subcommand("heartbeat", "wait for a heartbeat saying TEXT");
  beat->add_option("--url", url)->required();
  beat->add_option("--prefix", prefix)->required();
  auto* in_neighbours = beat->add_option("--contains", contains, "TEXT in its neighbours field");
  beat->add_option("--message", message, "TEXT in its message")->excludes(in_neighbours);
  beat->add_option("--steady", steady, "then K more heartbeats without a new plan");
  beat->add_option("--timeout", timeout_s);
  CLI11_PARSE(app, argc, argv);
  if (beat->parsed()) {
    if (contains.empty() && message.empty()) {
      std::cerr << "fleet_probe heartbeat: give --contains or --message\n";
      return 2;
    }
    robot_args = {prefix + "=-"};
  }

  std::vector<Robot> robots;
  for (const std::string& a : robot_args) {
    const auto [prefix, scene] = split(a);
    robots.push_back({prefix, lower(prefix), scene, {}, 0, std::nullopt, -1});
  }
  for (const std::string& a : newer_args) {
    const auto [prefix, id] = split(a);
    for (Robot& r : robots) {
      if (r.prefix == prefix) r.newer_than = std::stoll(id);
    }
  }
  for (Robot& r : robots) r.kept_plan_id = kept_plan_id(out_dir + "/" + r.name + ".json");
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "fleet_probe: LCM did not start on " << url << "\n";
    return 2;
  }
  struct Route {
    Robot* robot;
    bool plan;
    std::string suffix;
  };
  std::vector<Route> routes;
  routes.reserve(3 * robots.size());
  for (Robot& r : robots) {
    routes.push_back({&r, true, "_PLAN"});
    routes.push_back({&r, true, "_PLAN_CURRENT"});  // sent again for daemons that join late
    routes.push_back({&r, false, "_PLANNER_STATUS"});
  }
  for (Route& route : routes) {
    const std::string channel = route.robot->prefix + route.suffix;
    lcm.subscribeFunction(
           channel,
           +[](const lcm::ReceiveBuffer* rbuf, const std::string&, Route* r) {
             if (r->plan) {
               kinograph::plan_t msg;
               if (!kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size),
                                                     msg)
                        .ok) {
                 return;
               }
               ++r->robot->received;
               if (msg.status == kinograph::plan_t::SUCCESS) r->robot->plans[msg.plan_id] = msg;
             } else {
               kinograph::planner_status_t msg;
               if (kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size),
                                                    msg)
                       .ok) {
                 r->robot->heartbeat = msg;
               }
             }
           },
           &route)
        ->setQueueCapacity(1000);
  }
  std::cout << "ready" << std::endl;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  if (beat->parsed()) {
    const Robot& r = robots.front();
    const bool in_message = !message.empty();
    const std::string& text = in_message ? message : contains;
    const auto field = [&] { return in_message ? r.heartbeat->message : r.heartbeat->neighbours; };
    while (!r.heartbeat || field().find(text) == std::string::npos) {
      if (Clock::now() > deadline) {
        std::cerr << "fleet_probe: no heartbeat of " << prefix << " says '" << text << "' within "
                  << timeout_s << " s\n";
        return 1;
      }
      lcm.handleTimeout(50);
    }
    std::cout << field() << "\n";
    const int plans = r.heartbeat->num_plans;
    for (int beats = 0; beats < steady;) {
      const int64_t seen = r.heartbeat->utime;
      if (Clock::now() > deadline) {
        std::cerr << "fleet_probe: " << beats << " of " << steady << " heartbeats within "
                  << timeout_s << " s\n";
        return 1;
      }
      lcm.handleTimeout(50);
      if (r.heartbeat->utime == seen) continue;
      ++beats;
      if (r.heartbeat->num_plans != plans) {
        std::cerr << "fleet_probe: " << prefix << " published plan " << r.heartbeat->last_plan_id
                  << " after saying '" << text << "': " << r.heartbeat->message << "\n";
        return 1;
      }
    }
    if (steady > 0) {
      std::cout << prefix << ": " << plans << " plans, steady over " << steady << " heartbeats\n";
    }
    return 0;
  }
  std::string why = "nothing heard";
  while (!(why = unsettled(robots)).empty()) {
    if (Clock::now() > deadline) {
      std::cerr << "fleet_probe: not settled within " << timeout_s << " s: " << why << "\n";
      return 1;
    }
    lcm.handleTimeout(50);
  }
  for (const Robot& r : robots) {
    if (r.plans.count(r.heartbeat->valid_plan_id) == 0) {  // unchanged since the earlier run
      std::cout << r.prefix << ": plan " << r.kept_plan_id << " (kept), " << r.received
                << " plans received, " << r.heartbeat->num_neighbour_replans
                << " neighbour replans; neighbours: " << r.heartbeat->neighbours << "\n";
      continue;
    }
    const kinograph::plan_t& msg = r.plans.at(r.heartbeat->valid_plan_id);
    const kinograph::planning::Scene scene = kinograph::planning::load_scene(r.scene);
    nlohmann::json json =
        kinograph::planning::plan_to_json(kinograph::messages::plan_from_message(msg), scene);
    json["start_utime"] = msg.start_utime;
    json["plan_id"] = msg.plan_id;
    const std::string path = out_dir + "/" + r.name + ".json";
    std::ofstream(path) << json.dump(1) << "\n";
    std::cout << r.prefix << ": plan " << msg.plan_id << " (" << msg.method << "), " << r.received
              << " plans received, " << r.heartbeat->num_neighbour_replans
              << " neighbour replans; neighbours: " << r.heartbeat->neighbours << "\n";
  }
  return 0;
}
