// lcm_probe: the observer of the udpm integration tests of the simulator and of kinographd's
// Drake messages. It only listens, and waits on events with a bound, never on fixed sleeps.
//   lcm_probe states     --url URL --channel IIWA_STATE --count N [--near q,...] [--timeout S]
//       N consecutive states; prints their utime span and steps, the wall time they took, and
//       with --near the largest |q − near| over them.
//   lcm_probe wait-near  --url URL --channel IIWA_STATE --near q,... --tol RAD --count N
//       waits until N consecutive states are all within RAD of `near` (exit 1 on timeout).
//   lcm_probe drake-plan --url URL --channel COMMITTED_ROBOT_PLAN [--timeout S]
//       the first message on the channel: its fingerprint against Drake's lcmt_robot_plan
//       computed from Drake's member layout (tests/lcmtypes/lcm_fingerprint.h), then its knots.
// Each prints "ready" once subscribed, so a script can send what it is waiting for after that.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "drake/lcmt_robot_plan.hpp"
#include "kinograph/robot_state_t.hpp"
#include "lcmtypes/safe_decode.h"
#include "tests/lcmtypes/lcm_fingerprint.h"

namespace {

using Clock = std::chrono::steady_clock;

std::vector<double> parse(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) v.push_back(std::stod(item));
  return v;
}

// Collects raw messages on one channel, with their arrival times.
struct Inbox {
  struct Message {
    std::vector<uint8_t> bytes;
    Clock::time_point arrival;
  };
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    messages.push_back({std::vector<uint8_t>(data, data + rbuf->data_size), Clock::now()});
  }
  std::vector<Message> messages;
};

// Handles LCM until `done` holds or `timeout_s` passes; false on timeout.
template <typename Done>
bool pump(lcm::LCM& lcm, double timeout_s, Done done) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (Clock::now() > deadline) return false;
    if (lcm.handleTimeout(20) < 0) return false;
  }
  return true;
}

// Largest |q − near| of a state; infinite when a position is not finite, so that a diverged
// simulation never reads as "near".
double deviation(const kinograph::robot_state_t& s, const std::vector<double>& near) {
  double worst = 0;
  for (size_t j = 0; j < near.size() && j < s.position.size(); ++j) {
    const double d = std::abs(s.position[j] - near[j]);
    if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, d);
  }
  return worst;
}

kinograph::robot_state_t decode_state(const Inbox::Message& m) {
  kinograph::robot_state_t s;
  const auto status =
      kinograph::lcmtypes::safe_decode(m.bytes.data(), static_cast<int>(m.bytes.size()), s);
  if (!status.ok) throw std::runtime_error("a state did not decode: " + status.reason);
  return s;
}

// Drake's lcmt_robot_plan as Drake lays it out: a plan of timed knots (utime, int16 joint
// count, names, float positions).
int64_t drake_robot_plan_fingerprint() {
  using namespace kinograph::lcmtypes::testing;
  static const StructSpec knot{{member("utime", "int64_t"), member("num_joints", "int16_t"),
                                member("joint_name", "string", {var("num_joints")}),
                                member("joint_position", "float", {var("num_joints")})}};
  const StructSpec plan{{member("utime", "int64_t"), member("num_states", "int32_t"),
                         nested("plan", knot, {var("num_states")})}};
  return fingerprint(plan);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"lcm_probe: observer for the udpm integration tests"};
  app.require_subcommand(1);
  std::string url, channel, near_text;
  int count = 1;
  double timeout_s = 60, tol = 0;
  for (auto* sub :
       {app.add_subcommand("states", "statistics of N consecutive states"),
        app.add_subcommand("wait-near", "wait until N states are near q"),
        app.add_subcommand("drake-plan", "one Drake robot plan, fingerprint checked")}) {
    sub->add_option("--url", url, "LCM URL")->required();
    sub->add_option("--channel", channel, "channel")->required();
    sub->add_option("--timeout", timeout_s, "wall seconds to wait at most");
    if (sub->get_name() != "drake-plan") {
      sub->add_option("--count", count, "number of (consecutive) states");
      sub->add_option("--near", near_text, "reference joint positions, comma-separated");
    }
    if (sub->get_name() == "wait-near") sub->add_option("--tol", tol, "rad")->required();
  }
  CLI11_PARSE(app, argc, argv);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "lcm_probe: LCM could not start on " << url << "\n";
    return 1;
  }
  Inbox inbox;
  lcm.subscribe(channel, &Inbox::on_message, &inbox)->setQueueCapacity(100000);
  std::cout << "ready" << std::endl;
  const std::vector<double> near = parse(near_text);
  const std::string verb = app.get_subcommands()[0]->get_name();

  if (verb == "states") {
    if (!pump(lcm, timeout_s, [&] { return static_cast<int>(inbox.messages.size()) >= count; })) {
      std::cerr << "lcm_probe: " << inbox.messages.size() << " of " << count << " states\n";
      return 1;
    }
    int64_t first = 0, last = 0, min_step = INT64_MAX, max_step = 0;
    double worst = 0;
    for (int k = 0; k < count; ++k) {
      const kinograph::robot_state_t s = decode_state(inbox.messages[k]);
      if (k == 0) first = s.utime;
      if (k > 0) {
        min_step = std::min(min_step, s.utime - last);
        max_step = std::max(max_step, s.utime - last);
      }
      last = s.utime;
      if (!near.empty()) worst = std::max(worst, deviation(s, near));
    }
    const double wall_s =
        std::chrono::duration<double>(inbox.messages[count - 1].arrival - inbox.messages[0].arrival)
            .count();
    std::cout << "first_utime " << first << "\nlast_utime " << last << "\nmin_step_us "
              << (count > 1 ? min_step : 0) << "\nmax_step_us " << max_step << "\nwall_us "
              << std::llround(wall_s * 1e6) << "\nmax_deviation " << worst << "\n";
    return 0;
  }

  if (verb == "wait-near") {
    int run = 0;
    size_t seen = 0;
    double worst_last = 0;
    const bool ok = pump(lcm, timeout_s, [&] {
      for (; seen < inbox.messages.size(); ++seen) {
        worst_last = deviation(decode_state(inbox.messages[seen]), near);
        run = worst_last <= tol ? run + 1 : 0;
      }
      return run >= count;
    });
    std::cout << (ok ? "near" : "not near") << ": last deviation " << worst_last << " rad after "
              << seen << " states\n";
    return ok ? 0 : 1;
  }

  // drake-plan
  if (!pump(lcm, timeout_s, [&] { return !inbox.messages.empty(); })) {
    std::cerr << "lcm_probe: no message on " << channel << "\n";
    return 1;
  }
  const std::vector<uint8_t>& bytes = inbox.messages[0].bytes;
  int64_t head = 0;
  for (int i = 0; i < 8 && i < static_cast<int>(bytes.size()); ++i) head = (head << 8) | bytes[i];
  const int64_t expected = drake_robot_plan_fingerprint();
  if (head != expected) {
    std::cerr << "lcm_probe: fingerprint " << std::hex << head << " is not Drake's lcmt_robot_plan "
              << expected << "\n";
    return 1;
  }
  drake::lcmt_robot_plan plan;
  const auto status =
      kinograph::lcmtypes::safe_decode(bytes.data(), static_cast<int>(bytes.size()), plan);
  if (!status.ok || plan.num_states < 2) {
    std::cerr << "lcm_probe: the plan did not decode: " << status.reason << "\n";
    return 1;
  }
  std::cout << "fingerprint " << std::hex << head << std::dec << " is Drake's lcmt_robot_plan\n"
            << "utime " << plan.utime << "\nnum_states " << plan.num_states << "\nfirst_knot_utime "
            << plan.plan.front().utime << "\nlast_knot_utime " << plan.plan.back().utime
            << "\njoint_name_0 " << plan.plan.front().joint_name[0] << "\nfirst_q";
  for (float q : plan.plan.front().joint_position) std::cout << " " << q;
  std::cout << "\nlast_q";
  for (float q : plan.plan.back().joint_position) std::cout << " " << q;
  std::cout << "\n";
  return 0;
}
