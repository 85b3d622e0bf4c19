// Plan files: exact round trip of trajectories, stats and validation; the key names the
// renderer reads; joint reordering; infinities and NaN; errors that name the key.
#include "kinograph/planning/plan_json.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

namespace kinograph::planning {
namespace {

using nlohmann::json;

const std::string kSceneDir = std::string(KINOGRAPH_SOURCE_DIR) + "/robots/scenes/";

// A plan of the scene's size with seeded random values and every stats/validation field set.
Plan random_plan(const Problem& problem, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const int rows = problem.steps + 1, n = problem.model->nq();
  const auto random = [&] {
    Eigen::MatrixXd m(rows, n);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < n; ++j) m(i, j) = normal(rng);
    return m;
  };
  Plan plan;
  for (int k = 0; k < rows; ++k) plan.t.push_back(k * problem.dt());
  plan.q = random();
  plan.qd = random();
  plan.qdd = random();
  plan.tau = random();
  plan.stats.method = "batch-W";
  plan.stats.status = "converged";
  plan.stats.reason = "why not";
  plan.stats.iterations = 42;
  plan.stats.outer_iterations = 5;
  plan.stats.linear_solves = 84;
  plan.stats.attempts = 3;
  plan.stats.solve_time_s = 0.125;
  plan.stats.cost = 3.5;
  plan.stats.max_constraint_violation = 1.5e-5;
  Validation& v = plan.validation;
  v.valid = false;
  v.failures = {"dynamics residual 0.1 exceeds 0.001", "goal error 0.2 exceeds 0.01"};
  v.max_dynamics_residual = 0.1;
  v.max_position_consistency = 0.2;
  v.max_velocity_consistency = 0.3;
  v.max_q_violation = 0.4;
  v.max_qd_violation = 0.5;
  v.max_qdd_violation = 0.6;
  v.max_tau_violation = 0.7;
  v.min_clearance = -0.01;
  v.goal_error = 0.8;
  v.max_task_error = 0.9;
  v.max_unactuated_torque = 1.1;
  v.start_error = 1.2;
  v.final_velocity = 1.3;
  return plan;
}

void expect_same_plan(const Plan& a, const Plan& b) {
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.qd, b.qd);
  EXPECT_EQ(a.qdd, b.qdd);
  EXPECT_EQ(a.tau, b.tau);
  EXPECT_EQ(a.stats.method, b.stats.method);
  EXPECT_EQ(a.stats.status, b.stats.status);
  EXPECT_EQ(a.stats.reason, b.stats.reason);
  EXPECT_EQ(a.stats.iterations, b.stats.iterations);
  EXPECT_EQ(a.stats.outer_iterations, b.stats.outer_iterations);
  EXPECT_EQ(a.stats.linear_solves, b.stats.linear_solves);
  EXPECT_EQ(a.stats.attempts, b.stats.attempts);
  EXPECT_EQ(a.stats.solve_time_s, b.stats.solve_time_s);
  EXPECT_EQ(a.stats.cost, b.stats.cost);
  EXPECT_EQ(a.stats.max_constraint_violation, b.stats.max_constraint_violation);
  const Validation &v = a.validation, &w = b.validation;
  EXPECT_EQ(v.valid, w.valid);
  EXPECT_EQ(v.failures, w.failures);
  EXPECT_EQ(v.max_dynamics_residual, w.max_dynamics_residual);
  EXPECT_EQ(v.max_position_consistency, w.max_position_consistency);
  EXPECT_EQ(v.max_velocity_consistency, w.max_velocity_consistency);
  EXPECT_EQ(v.max_q_violation, w.max_q_violation);
  EXPECT_EQ(v.max_qd_violation, w.max_qd_violation);
  EXPECT_EQ(v.max_qdd_violation, w.max_qdd_violation);
  EXPECT_EQ(v.max_tau_violation, w.max_tau_violation);
  EXPECT_EQ(v.min_clearance, w.min_clearance);
  EXPECT_EQ(v.goal_error, w.goal_error);
  EXPECT_EQ(v.max_task_error, w.max_task_error);
  EXPECT_EQ(v.max_unactuated_torque, w.max_unactuated_torque);
  EXPECT_EQ(v.start_error, w.start_error);
  EXPECT_EQ(v.final_velocity, w.final_velocity);
}

TEST(PlanJson, RoundTripsExactlyThroughAFile) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  const Plan plan = random_plan(scene.problem, 7);
  const std::string path =
      (std::filesystem::temp_directory_path() / "kinograph_plan_json_test" / "plan.json").string();
  write_plan(plan, scene, path);  // creates the directory
  expect_same_plan(plan, read_plan(path, *scene.problem.model));
}

TEST(PlanJson, HasTheKeysTheRendererReads) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  const Plan plan = random_plan(scene.problem, 3);
  const json j = plan_to_json(plan, scene);
  EXPECT_EQ(j["robot"]["urdf"], "robots/iiwa14/iiwa14.urdf");  // relative to the repo root
  EXPECT_EQ(j["robot"]["payload"]["frame"], "iiwa_link_ee_kuka");
  EXPECT_EQ(j["robot"]["payload"]["mass"], 2.0);
  EXPECT_EQ(j["robot"]["payload"]["size"], json({0.1, 0.1, 0.1}));
  EXPECT_EQ(j["robot"]["payload"]["offset"], json({0.0, 0.0, 0.05}));
  ASSERT_EQ(j["obstacles"].size(), 5u);
  const json& top = j["obstacles"][0];
  EXPECT_EQ(top["id"], "desk_top");
  EXPECT_EQ(top["shape"], "box");
  EXPECT_EQ(top["size"], json({0.5, 1.0, 0.04}));
  EXPECT_EQ(top["position"], json({0.75, 0.0, 0.64}));
  EXPECT_EQ(top["quaternion"], json({1.0, 0.0, 0.0, 0.0}));
  EXPECT_FALSE(top.contains("motion"));
  ASSERT_EQ(j["joint_names"].size(), 7u);
  EXPECT_EQ(j["joint_names"][0], "iiwa_joint_1");
  EXPECT_EQ(j["t"].size(), 31u);
  for (const char* key : {"q", "qd", "qdd", "tau"}) {
    ASSERT_EQ(j[key].size(), 31u) << key;
    EXPECT_EQ(j[key][0].size(), 7u) << key;
  }
  EXPECT_EQ(j["q"][4][2], plan.q(4, 2));
  EXPECT_EQ(j["tau"][30][6], plan.tau(30, 6));
  EXPECT_EQ(j["limits"]["effort"][0], 320.0);
  EXPECT_EQ(j["limits"]["velocity"].size(), 7u);
  EXPECT_EQ(j["stats"]["iterations"], 42);
  EXPECT_EQ(j["validation"]["failures"].size(), 2u);
  EXPECT_EQ(j["validation"]["valid"], false);
}

TEST(PlanJson, ShapesMotionAndInfinities) {
  const Scene scene = parse_scene(R"(robot: {urdf: robots/rr/rr.urdf}
horizon: 1
steps: 4
start: {q: [0, 0]}
goal: {q: [1, 0]}
limits: {joint1: {effort: .inf, lower: -.inf}}
obstacles:
  - {id: s, shape: sphere, size: [0.2], position: [1, 0, 1]}
  - {id: c, shape: capsule, size: [0.1, 0.3], rpy: [0, pi/2, 0]}
  - id: m
    shape: cylinder
    size: [0.1, 0.4]
    motion: [{t: 0, position: [0, 0, 2]}, {t: 1, position: [0, 1, 2]}]
)");
  Plan plan = random_plan(scene.problem, 5);
  plan.validation.min_clearance = std::numeric_limits<double>::infinity();
  plan.q(2, 1) = std::numeric_limits<double>::quiet_NaN();
  const json j = plan_to_json(plan, scene);
  EXPECT_EQ(j["obstacles"][0]["size"], json({0.2}));
  EXPECT_EQ(j["obstacles"][1]["size"], json({0.1, 0.3}));
  const json& q = j["obstacles"][1]["quaternion"];
  EXPECT_NEAR(q[0].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q[2].get<double>(), std::sqrt(0.5), 1e-12);
  ASSERT_EQ(j["obstacles"][2]["motion"].size(), 2u);
  EXPECT_EQ(j["obstacles"][2]["motion"][1]["t"], 1.0);
  EXPECT_EQ(j["obstacles"][2]["motion"][1]["position"], json({0.0, 1.0, 2.0}));
  // An infinite effort limit leaves "effort" out (the renderer wants numbers); others are null.
  EXPECT_FALSE(j["limits"].contains("effort"));
  EXPECT_TRUE(j["limits"]["lower"][0].is_null());
  EXPECT_TRUE(j["validation"]["min_clearance"].is_null());
  EXPECT_TRUE(j["q"][2][1].is_null());
  // And back: null clearance is +inf, a null trajectory value NaN.
  const Plan back = plan_from_json(json::parse(j.dump()), *scene.problem.model);
  EXPECT_EQ(back.validation.min_clearance, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(back.q(2, 1)));
  EXPECT_EQ(back.q(2, 0), plan.q(2, 0));
}

TEST(PlanJson, ColumnsFollowJointNames) {
  const Scene scene = load_scene(kSceneDir + "rr_reach.yaml");
  const Plan plan = random_plan(scene.problem, 11);
  json j = plan_to_json(plan, scene);
  // Swap the two columns and their names: reading must give the model's order back.
  j["joint_names"] = {"joint2", "joint1"};
  for (const char* key : {"q", "qd", "qdd", "tau"}) {
    for (json& row : j[key]) std::swap(row[0], row[1]);
  }
  expect_same_plan(plan, plan_from_json(j, *scene.problem.model));
  // Without names, columns are taken in order.
  j.erase("joint_names");
  const Plan unnamed = plan_from_json(j, *scene.problem.model);
  EXPECT_EQ(unnamed.q.col(0), plan.q.col(1));
}

// The error's message, which must name the plan and the key.
std::string error_of(const json& j, const dynamics::Model& model) {
  try {
    plan_from_json(j, model, "p.json");
  } catch (const PlanFileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PlanJson, ErrorsNameTheKey) {
  const Scene scene = load_scene(kSceneDir + "rr_reach.yaml");
  const dynamics::Model& model = *scene.problem.model;
  const json good = plan_to_json(random_plan(scene.problem, 1), scene);
  const auto broken = [&](auto edit) {
    json j = good;
    edit(j);
    return error_of(j, model);
  };
  EXPECT_NE(broken([](json& j) { j.erase("qd"); }).find("'qd'"), std::string::npos);
  EXPECT_NE(broken([](json& j) { j["q"][3].push_back(1.0); }).find("'q[3]'"), std::string::npos);
  EXPECT_NE(broken([](json& j) { j["tau"].erase(0); }).find("'tau'"), std::string::npos);
  EXPECT_NE(broken([](json& j) { j["joint_names"][1] = "wrist"; }).find("joint2"),
            std::string::npos);
  EXPECT_NE(broken([](json& j) { j["t"][2] = j["t"][1]; }).find("'t[2]'"), std::string::npos);
  EXPECT_NE(broken([](json& j) { j["stats"]["iterations"] = "many"; }).find("stats.iterations"),
            std::string::npos);
  EXPECT_NE(
      broken([](json& j) { j["validation"]["goal_error"] = "x"; }).find("validation.goal_error"),
      std::string::npos);
  EXPECT_NE(broken([](json& j) { j["q"][0][0] = "x"; }).find("p.json"), std::string::npos);
  EXPECT_THROW(read_plan("/no/such/plan.json", model), PlanFileError);
}

}  // namespace
}  // namespace kinograph::planning
