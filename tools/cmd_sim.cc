// The simulated robot and the setpoints it follows:
//   kinograph sim          SCENE [--prefix IIWA] [--slowdown 10] [--start-utime US]
//                          [--duration S] [--payload-mass-error KG] [--position-noise RAD]
//                          [--velocity-noise RAD/S] [--seed N] [--iiwa-status-channel CH]
//   kinograph send-command --prefix IIWA --scene S --q ... [--qd ...] (--tau ... | --gravity)
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <memory>

#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/planning/io/scene.h"
#include "sim/sim_node.h"
#include "tools/command_registry.h"
#include "tools/lcm_client.h"
#include "tools/number_list.h"

namespace kinograph::tools {
namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

// A comma-separated list of exactly n numbers for `option`, one per joint.
Eigen::VectorXd parse_joints(const std::string& text, const std::string& option, int n) {
  std::vector<double> values = parse_number_list(text, option, static_cast<std::size_t>(n));
  return Eigen::Map<Eigen::VectorXd>(values.data(), n);
}

const bool kSim = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand(
      "sim", "simulate the scene's robot on LCM: follow <PREFIX>_COMMAND, publish <PREFIX>_STATE");
  auto scene = std::make_shared<std::string>();
  auto o = std::make_shared<sim::SimNodeOptions>();
  sub->add_option("scene", *scene, "scene file (robot, payload, start state)")->required();
  sub->add_option("--prefix", o->channel_prefix,
                  "channel prefix (default: robot name upper-cased)");
  sub->add_option("--lcm-url", o->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  sub->add_option("--slowdown", o->slowdown,
                  "wall-clock seconds per simulated second, e.g. 10 for sim time ten times "
                  "slower than real time (default 1)");
  sub->add_option("--start-utime", o->start_utime,
                  "the robot's clock at the start, µs (default: the wall clock)");
  sub->add_option("--duration", o->duration_s, "simulated seconds to run (default: until stopped)");
  sub->add_option("--payload-mass-error", o->payload_mass_error_kg,
                  "kg added to the last link at its centre of mass, which the planner and the "
                  "feed-forward do not know (negative: lighter; default 0)");
  sub->add_option("--position-noise", o->position_noise,
                  "standard deviation of the published positions, rad (default 0)");
  sub->add_option("--velocity-noise", o->velocity_noise,
                  "standard deviation of the published velocities, rad/s (default 0)");
  sub->add_option("--seed", o->seed, "seed of the sensor noise (default 1)");
  sub->add_option("--iiwa-status-channel", o->iiwa_status_channel,
                  "also publish Drake's lcmt_iiwa_status on this channel, e.g. IIWA_STATUS");
  sub->callback([=] {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    // The tracking-error lines are the simulator's output; the CLI's default level hides info.
    if (spdlog::get_level() == spdlog::level::warn) spdlog::set_level(spdlog::level::info);
    sim::SimNode node(planning::load_scene(*scene), *o);
    node.run(g_stop);
    const sim::TrackingStats& t = node.tracking();
    std::cout << "kinograph sim: tracking error max " << t.max << " rad, rms " << t.rms()
              << " rad over " << t.samples << " states; " << node.commands_received()
              << " commands, " << node.commands_rejected() << " refused\n";
  });
});

const bool kSendCommand = register_command([](CLI::App& root) {
  auto* sub = root.add_subcommand("send-command", "publish one joint_command_t setpoint");
  auto prefix = std::make_shared<std::string>();
  auto url = std::make_shared<std::string>();
  auto scene = std::make_shared<std::string>();
  auto q = std::make_shared<std::string>();
  auto qd = std::make_shared<std::string>();
  auto tau = std::make_shared<std::string>();
  auto gravity = std::make_shared<bool>(false);
  auto utime = std::make_shared<int64_t>(0);
  sub->add_option("--prefix", *prefix, "channel prefix of the robot, e.g. IIWA")->required();
  sub->add_option("--lcm-url", *url, "LCM URL (default: $LCM_DEFAULT_URL or udpm)");
  sub->add_option("--scene", *scene, "scene with the robot (joint names, --gravity's model)")
      ->required();
  sub->add_option("--q", *q, "joint positions, comma-separated, rad")->required();
  sub->add_option("--qd", *qd, "joint velocities, rad/s (default zeros)");
  auto* tau_option = sub->add_option("--tau", *tau, "feed-forward torques, N·m (default zeros)");
  sub->add_flag("--gravity", *gravity,
                "feed-forward the scene model's gravity torque at q, to hold q at rest")
      ->excludes(tau_option);
  sub->add_option("--utime", *utime, "the setpoint's time on the robot's clock, µs (default 0)");
  sub->callback([=] {
    const planning::Scene s = planning::load_scene(*scene);
    const dynamics::Model& model = *s.problem.model;
    const int n = model.nq();
    messages::CommandSetpoint setpoint;
    setpoint.utime = *utime;
    setpoint.q = parse_joints(*q, "--q", n);
    setpoint.qd =
        qd->empty() ? Eigen::VectorXd(Eigen::VectorXd::Zero(n)) : parse_joints(*qd, "--qd", n);
    setpoint.tau =
        tau->empty() ? Eigen::VectorXd(Eigen::VectorXd::Zero(n)) : parse_joints(*tau, "--tau", n);
    if (*gravity) {
      dynamics::Data data(model);
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
      setpoint.tau = dynamics::rnea(model, data, setpoint.q, zero, zero);
    }
    const joint_command_t msg = messages::command_to_message(setpoint, model);
    open_lcm(*url).publish(*prefix + "_COMMAND", &msg);
    std::cout << "sent command on " << *prefix << "_COMMAND\n";
  });
});

}  // namespace
}  // namespace kinograph::tools
