// Table I's Acrobot beside OMPL's control-space planners (SST, RRT, KPIECE1) on the same
// dynamics: the URDF's forward dynamics integrated by RK4 (the simulator's integrator), the
// same elbow torque and joint velocity limits, from the hanging rest to an upright goal at
// rest, with at most `horizon` seconds of motion. kinograph plans the scene; the OMPL planners
// search with the scene's limits and stop at their first solution.
#include <ompl/base/OptimizationObjective.h>
#include <ompl/base/ProjectionEvaluator.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>
#include <ompl/control/SimpleSetup.h>
#include <ompl/control/planners/kpiece/KPIECE1.h>
#include <ompl/control/planners/rrt/RRT.h>
#include <ompl/control/planners/sst/SST.h>
#include <ompl/control/spaces/RealVectorControlSpace.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>
#include <spdlog/spdlog.h>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "bench/common/cpu_clock.h"
#include "bench/common/timed_plan.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/batch/batch_planner.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/sim/rigid_body_sim.h"

namespace ob = ompl::base;
namespace oc = ompl::control;
using kinograph::bench::cell;
using nlohmann::json;

namespace {

using kinograph::bench::cpu_seconds;

/// One Acrobot problem as both sides see it: the model with the scene's limits, the elbow's
/// torque bound, one velocity bound for both joints, the horizon and the goal tolerance.
struct Setting {
  std::string name, scene;
  kinograph::planning::Scene loaded;
  double effort = 0, vmax = 0, horizon = 0;
};

/// The goal region: the tip within `tip_tol` of the upright tip and every |q̇| ≤ `qd_tol`.
constexpr double kTipTolerance = 0.1;   // m
constexpr double kRestTolerance = 1.0;  // rad/s
/// OMPL propagates in steps of this length, each integrated by RK4 in kSubsteps steps.
constexpr double kPropagationStep = 0.05;  // s
constexpr int kSubsteps = 5;

/// The state layout: shoulder and elbow angles (SO2), their velocities, and time (weight 0 in
/// the metric), so that a motion's duration is its cost and the horizon a state bound.
class AcrobotSpace {
 public:
  AcrobotSpace(const kinograph::dynamics::Model& model, const Setting& s)
      : model_(model), data_(model), sim_(model), tip_(model.frame_index("tip")) {
    auto angles1 = std::make_shared<ob::SO2StateSpace>();
    auto angles2 = std::make_shared<ob::SO2StateSpace>();
    auto rates = std::make_shared<ob::RealVectorStateSpace>(2);
    rates->setBounds(-s.vmax, s.vmax);
    auto time = std::make_shared<ob::RealVectorStateSpace>(1);
    time->setBounds(0.0, s.horizon);
    auto space = std::make_shared<ob::CompoundStateSpace>();
    space->addSubspace(angles1, 1.0);
    space->addSubspace(angles2, 1.0);
    space->addSubspace(rates, 0.25);  // 1 rad/s counts as 0.25 rad
    space->addSubspace(time, 0.0);
    space->lock();
    space_ = space;
    gains_.kp = Eigen::MatrixXd::Zero(2, 2);
    gains_.kd = Eigen::MatrixXd::Zero(2, 2);
    gains_.actuated = Eigen::Vector2d(0, 1);
    setpoint_.q = setpoint_.qd = setpoint_.tau = Eigen::VectorXd::Zero(2);
    forward_kinematics(Eigen::Vector2d(M_PI, 0.0));
    upright_tip_ = tip();
  }

  const ob::StateSpacePtr& space() const { return space_; }

  static void read(const ob::State* s, Eigen::Vector2d& q, Eigen::Vector2d& qd, double& t) {
    const auto* c = s->as<ob::CompoundState>();
    q << c->as<ob::SO2StateSpace::StateType>(0)->value,
        c->as<ob::SO2StateSpace::StateType>(1)->value;
    const double* r = c->as<ob::RealVectorStateSpace::StateType>(2)->values;
    qd << r[0], r[1];
    t = c->as<ob::RealVectorStateSpace::StateType>(3)->values[0];
  }
  static void write(ob::State* s, const Eigen::Vector2d& q, const Eigen::Vector2d& qd, double t) {
    auto* c = s->as<ob::CompoundState>();
    c->as<ob::SO2StateSpace::StateType>(0)->value = q[0];
    c->as<ob::SO2StateSpace::StateType>(1)->value = q[1];
    double* r = c->as<ob::RealVectorStateSpace::StateType>(2)->values;
    r[0] = qd[0];
    r[1] = qd[1];
    c->as<ob::RealVectorStateSpace::StateType>(3)->values[0] = t;
  }

  /// RK4 of the forward dynamics under a constant elbow torque for `duration` seconds.
  void propagate(const ob::State* from, double elbow_torque, double duration, ob::State* to) {
    Eigen::Vector2d q, qd;
    double t;
    read(from, q, qd, t);
    kinograph::sim::JointState state{q, qd};
    setpoint_.tau[1] = elbow_torque;
    const int n =
        std::max(1, static_cast<int>(std::lround(duration / kPropagationStep * kSubsteps)));
    try {
      for (int i = 0; i < n; ++i) sim_.step(duration / n, gains_, setpoint_, state);
    } catch (const std::runtime_error&) {
      state.qd.setConstant(1e9);  // diverged: out of the velocity bounds, so invalid
    }
    write(to, state.q, state.qd, t + duration);
    space_->enforceBounds(to);  // wraps the angles only: velocities and time stay as computed
    to->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(2)->values[0] =
        state.qd[0];
    to->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(2)->values[1] =
        state.qd[1];
    to->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(3)->values[0] =
        t + duration;
  }

  /// Distance of the tip from the upright tip, in metres.
  double tip_error(const Eigen::Vector2d& q) {
    forward_kinematics(q);
    return (tip() - upright_tip_).norm();
  }

 private:
  void forward_kinematics(const Eigen::Vector2d& q) {
    kinograph::dynamics::forward_kinematics(model_, data_, q);
  }
  Eigen::Vector3d tip() const {
    return kinograph::dynamics::frame_pose(model_, data_, tip_).translation();
  }

  const kinograph::dynamics::Model& model_;
  kinograph::dynamics::Data data_;
  kinograph::sim::RigidBodySim sim_;
  kinograph::sim::PdGains gains_;
  kinograph::sim::Setpoint setpoint_;
  int tip_;
  Eigen::Vector3d upright_tip_;
  ob::StateSpacePtr space_;
};

/// The upright at rest, as a goal region OMPL's planners can also sample (goal bias).
class UprightGoal : public ob::GoalSampleableRegion {
 public:
  UprightGoal(const oc::SpaceInformationPtr& si, AcrobotSpace& acrobot, double horizon)
      : ob::GoalSampleableRegion(si), acrobot_(acrobot), horizon_(horizon) {
    setThreshold(1.0);
  }
  /// max(tip error / tolerance, max |q̇| / tolerance): ≤ 1 inside the region.
  double distanceGoal(const ob::State* s) const override {
    Eigen::Vector2d q, qd;
    double t;
    AcrobotSpace::read(s, q, qd, t);
    return std::max(acrobot_.tip_error(q) / kTipTolerance,
                    qd.cwiseAbs().maxCoeff() / kRestTolerance);
  }
  void sampleGoal(ob::State* s) const override {
    const Eigen::Vector2d q(M_PI + rng_.uniformReal(-0.02, 0.02), rng_.uniformReal(-0.02, 0.02));
    const Eigen::Vector2d qd(rng_.uniformReal(-kRestTolerance, kRestTolerance),
                             rng_.uniformReal(-kRestTolerance, kRestTolerance));
    AcrobotSpace::write(s, q, qd, rng_.uniformReal(0, horizon_));
    si_->enforceBounds(s);  // wraps the angles into SO2's range
  }
  unsigned int maxSampleCount() const override { return std::numeric_limits<unsigned>::max(); }

 private:
  AcrobotSpace& acrobot_;
  double horizon_;
  mutable ompl::RNG rng_;
};

/// A motion's cost is its duration (the time coordinate's increase), so SST's cost threshold
/// can say "any solution within the horizon": it stops at its first one, as RRT and KPIECE1 do.
class DurationObjective : public ob::OptimizationObjective {
 public:
  DurationObjective(const ob::SpaceInformationPtr& si, double horizon)
      : ob::OptimizationObjective(si) {
    setCostThreshold(ob::Cost(horizon + 1e-9));
  }
  ob::Cost stateCost(const ob::State*) const override { return identityCost(); }
  ob::Cost motionCost(const ob::State* a, const ob::State* b) const override {
    Eigen::Vector2d q, qd;
    double ta, tb;
    AcrobotSpace::read(a, q, qd, ta);
    AcrobotSpace::read(b, q, qd, tb);
    return ob::Cost(tb - ta);
  }
};

/// KPIECE1's grid: the two joint angles.
class AnglesProjection : public ob::ProjectionEvaluator {
 public:
  explicit AnglesProjection(const ob::StateSpacePtr& space) : ob::ProjectionEvaluator(space) {}
  unsigned int getDimension() const override { return 2; }
  void defaultCellSizes() override { cellSizes_ = {2 * M_PI / 20, 2 * M_PI / 20}; }
  void project(const ob::State* s, Eigen::Ref<Eigen::VectorXd> out) const override {
    Eigen::Vector2d q, qd;
    double t;
    AcrobotSpace::read(s, q, qd, t);
    out = q;
  }
};

/// One run's outcome: solved within the cap (CPU seconds), its wall time and where the motion ends.
struct Outcome {
  bool success = false;
  double wall_s = 0, cpu_s = 0, duration_s = NAN, tip_error_m = NAN, end_speed = NAN;
  bool valid = false;  // kinograph only: the plan passed validate
};

Outcome run_ompl(const std::string& planner_name, const kinograph::dynamics::Model& model,
                 const Setting& s, double cap_s) {
  AcrobotSpace acrobot(model, s);
  auto controls = std::make_shared<oc::RealVectorControlSpace>(acrobot.space(), 1);
  ob::RealVectorBounds torque(1);
  torque.setLow(-s.effort);
  torque.setHigh(s.effort);
  controls->setBounds(torque);
  oc::SimpleSetup setup(controls);
  const oc::SpaceInformationPtr& si = setup.getSpaceInformation();
  acrobot.space()->registerDefaultProjection(std::make_shared<AnglesProjection>(acrobot.space()));
  setup.setStateValidityChecker([&si](const ob::State* st) { return si->satisfiesBounds(st); });
  setup.setStatePropagator([&acrobot](const ob::State* from, const oc::Control* u, double dt,
                                      ob::State* to) {
    acrobot.propagate(from, u->as<oc::RealVectorControlSpace::ControlType>()->values[0], dt, to);
  });
  si->setPropagationStepSize(kPropagationStep);
  si->setMinMaxControlDuration(1, 10);
  ob::ScopedState<> start(acrobot.space());
  AcrobotSpace::write(start.get(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), 0.0);
  setup.setStartState(start);
  setup.setGoal(std::make_shared<UprightGoal>(si, acrobot, s.horizon));
  setup.getProblemDefinition()->setOptimizationObjective(
      std::make_shared<DurationObjective>(si, s.horizon));
  if (planner_name == "SST") setup.setPlanner(std::make_shared<oc::SST>(si));
  if (planner_name == "RRT") setup.setPlanner(std::make_shared<oc::RRT>(si));
  if (planner_name == "KPIECE1") setup.setPlanner(std::make_shared<oc::KPIECE1>(si));
  setup.setup();

  Outcome out;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_seconds();
  // The cap is on CPU time, so a loaded machine does not cut a search short.
  const ob::PlannerStatus status =
      setup.solve(ob::PlannerTerminationCondition([&] { return cpu_seconds() - c0 > cap_s; }));
  out.cpu_s = cpu_seconds() - c0;
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.success = status == ob::PlannerStatus::EXACT_SOLUTION;
  if (setup.haveSolutionPath()) {
    oc::PathControl& path = setup.getSolutionPath();
    Eigen::Vector2d q, qd;
    double t;
    AcrobotSpace::read(path.getStates().back(), q, qd, t);
    out.duration_s = t;
    out.tip_error_m = acrobot.tip_error(q);
    out.end_speed = qd.cwiseAbs().maxCoeff();
  }
  return out;
}

Outcome run_kinograph(const kinograph::dynamics::Model& model, const Setting& s) {
  const kinograph::planning::BatchPlanner planner;
  const double c0 = cpu_seconds();
  const kinograph::bench::Run run = kinograph::bench::plan_once(planner, s.loaded.problem);
  Outcome out;
  out.cpu_s = cpu_seconds() - c0;
  out.wall_s = run.wall_s;
  out.valid = run.plan.validation.valid;
  out.success = run.plan.success();
  const kinograph::planning::Plan& plan = run.plan;
  if (plan.q.rows() > 0) {
    AcrobotSpace acrobot(model, s);
    const Eigen::Vector2d q = plan.q.bottomRows<1>().transpose();
    const Eigen::Vector2d qd = plan.qd.bottomRows<1>().transpose();
    out.duration_s = plan.t.back() - plan.t.front();
    out.tip_error_m = acrobot.tip_error(q);
    out.end_speed = qd.cwiseAbs().maxCoeff();
  }
  return out;
}

// Reads or writes exactly n bytes; false at end of file or on error.
bool read_all(int fd, void* data, std::size_t n) {
  auto* p = static_cast<char*>(data);
  while (n > 0) {
    const ssize_t got = ::read(fd, p, n);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    p += got;
    n -= static_cast<std::size_t>(got);
  }
  return true;
}
bool write_all(int fd, const void* data, std::size_t n) {
  const auto* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t put = ::write(fd, p, n);
    if (put < 0 && errno == EINTR) continue;
    if (put <= 0) return false;
    p += put;
    n -= static_cast<std::size_t>(put);
  }
  return true;
}

/// kinograph's runs, in a child process of its own (forked before any search, serving one
/// run per request over a pipe). A deployed planner runs in a daemon of its own; in this
/// process OMPL's searches leave glibc's heap with millions of freed small blocks, which slow
/// every later allocation of the planner by about half.
class KinographProcess {
 public:
  /// Forks the child that plans `cases` (which must outlive this). Throws std::runtime_error
  /// when the pipes or the fork fail.
  explicit KinographProcess(const std::vector<Setting>& cases) {
    int request[2], reply[2];
    if (::pipe(request) != 0 || ::pipe(reply) != 0) throw std::runtime_error("pipe failed");
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::close(request[1]);
      ::close(reply[0]);
      int index = 0;
      while (read_all(request[0], &index, sizeof index)) {
        const Setting& s = cases.at(static_cast<std::size_t>(index));
        const Outcome out = run_kinograph(*s.loaded.problem.model, s);
        if (!write_all(reply[1], &out, sizeof out)) break;
      }
      ::_exit(0);
    }
    ::close(request[0]);
    ::close(reply[1]);
    request_ = request[1];
    reply_ = reply[0];
  }
  ~KinographProcess() {
    ::close(request_);  // the child sees the end of its requests and exits
    ::close(reply_);
    ::waitpid(pid_, nullptr, 0);
  }
  KinographProcess(const KinographProcess&) = delete;
  KinographProcess& operator=(const KinographProcess&) = delete;

  /// One plan of case `index`, timed in the child. Throws std::runtime_error if the child is
  /// gone.
  Outcome run(int index) {
    Outcome out;
    if (!write_all(request_, &index, sizeof index) || !read_all(reply_, &out, sizeof out)) {
      throw std::runtime_error("kinograph's planning process ended");
    }
    return out;
  }

 private:
  pid_t pid_ = -1;
  int request_ = -1, reply_ = -1;
};

json summary(const std::vector<Outcome>& runs) {
  using kinograph::bench::max_of;
  using kinograph::bench::mean;
  using kinograph::bench::median;
  std::vector<double> wall, cpu, solved_wall, tip, speed, duration;
  int ok = 0;
  for (const Outcome& o : runs) {
    wall.push_back(o.wall_s);
    cpu.push_back(o.cpu_s);
    if (!o.success) continue;
    ++ok;
    solved_wall.push_back(o.wall_s);
    tip.push_back(o.tip_error_m);
    speed.push_back(o.end_speed);
    duration.push_back(o.duration_s);
  }
  // Times are over every run (a failure counts with the time it took, at most the cap).
  return {{"runs", runs.size()},
          {"successes", ok},
          {"median_s", median(wall)},
          {"mean_s", mean(wall)},
          {"median_cpu_s", median(cpu)},
          {"max_s", max_of(wall)},
          {"median_solved_s", median(solved_wall)},
          {"median_end_tip_error_m", median(tip)},
          {"median_end_speed_rad_s", median(speed)},
          {"median_duration_s", median(duration)}};
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 20, seed = 1;
  double cap_s = 20;
  std::string json_path, settings = "8nm";
  bool quick = false;
  kinograph::bench::Flags flags("acrobot_ompl_bench");
  flags.value("--seeds", &seeds)
      .value("--seed", &seed)
      .value("--cap", &cap_s)
      .value("--settings", "8nm|4nm|both",
             [&](const std::string& v) {
               if (v != "8nm" && v != "4nm" && v != "both") throw std::invalid_argument(v);
               settings = v;
             })
      .value("--json", &json_path)
      .toggle("--quick", [&] { quick = true; });
  if (!flags.parse(argc, argv)) return 64;
  if (quick) {
    seeds = std::min(seeds, 4);
    cap_s = std::min(cap_s, 5.0);
  }
  spdlog::set_level(spdlog::level::warn);
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(seed));

  std::vector<Setting> cases;
  auto add = [&](const std::string& name, const std::string& scene) {
    Setting s;
    s.name = name;
    s.scene = scene;
    s.loaded = kinograph::planning::load_scene(kinograph::bench::kScenes + scene);
    const auto& bodies = s.loaded.problem.model->bodies;
    s.effort = bodies.at(1).limits.effort;
    s.vmax = std::min(bodies.at(0).limits.velocity, bodies.at(1).limits.velocity);
    s.horizon = s.loaded.problem.horizon;
    cases.push_back(std::move(s));
  };
  if (settings != "4nm") add("8nm", "acrobot_swingup.yaml");
  if (settings != "8nm") add("4nm", "acrobot_swingup_4nm.yaml");

  const std::vector<std::string> methods = {"kinograph", "SST", "RRT", "KPIECE1"};
  json result = {{"seeds", seeds},
                 {"seed", seed},
                 {"cap_s", cap_s},
                 {"tip_tolerance_m", kTipTolerance},
                 {"rest_tolerance_rad_s", kRestTolerance},
                 {"propagation_step_s", kPropagationStep},
                 {"rk4_substeps", kSubsteps},
                 {"kinograph_in_own_process", true}};
  KinographProcess kinograph_process(cases);  // before OMPL has allocated anything
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const Setting& s = cases[c];
    const kinograph::dynamics::Model& model = *s.loaded.problem.model;
    std::vector<std::vector<Outcome>> runs(methods.size());
    for (int i = 0; i < seeds; ++i) {  // interleaved: every method once per seed
      for (std::size_t m = 0; m < methods.size(); ++m) {
        runs[m].push_back(m == 0 ? kinograph_process.run(static_cast<int>(c))
                                 : run_ompl(methods[m], model, s, cap_s));
      }
      std::cerr << s.name << " seed " << i + 1 << "/" << seeds << "\n";
    }
    json setting = {{"scene", s.scene},
                    {"effort_nm", s.effort},
                    {"velocity_limit_rad_s", s.vmax},
                    {"horizon_s", s.horizon}};
    for (std::size_t m = 0; m < methods.size(); ++m) setting[methods[m]] = summary(runs[m]);
    result[s.name] = setting;
  }

  if (!json_path.empty()) std::ofstream(json_path) << result.dump(2) << "\n";
  std::printf(
      "| setting | method | success | median CPU (s) | median (s) | mean (s) | max (s) | end tip "
      "error (m) | end max \\|q̇\\| (rad/s) | motion (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Setting& s : cases) {
    const json& setting = result[s.name];
    for (const std::string& m : methods) {
      const json& r = setting[m];
      std::printf("| ±%.0f N·m, \\|q̇\\| ≤ %.0f | %s | %d/%d | %s | %s | %s | %s | %s | %s | %s |\n",
                  s.effort, s.vmax, m.c_str(), r["successes"].get<int>(), r["runs"].get<int>(),
                  cell(kinograph::bench::json_number(r["median_cpu_s"]), 1, 3).c_str(),
                  cell(kinograph::bench::json_number(r["median_s"]), 1, 3).c_str(),
                  cell(kinograph::bench::json_number(r["mean_s"]), 1, 3).c_str(),
                  cell(kinograph::bench::json_number(r["max_s"]), 1, 3).c_str(),
                  cell(kinograph::bench::json_number(r["median_end_tip_error_m"]), 1, 3).c_str(),
                  cell(kinograph::bench::json_number(r["median_end_speed_rad_s"]), 1, 2).c_str(),
                  cell(kinograph::bench::json_number(r["median_duration_s"]), 1, 2).c_str());
    }
  }
  return 0;
}
