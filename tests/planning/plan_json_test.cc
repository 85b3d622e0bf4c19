// Plan files: exact round trip of trajectories, stats and validation; the key names the
// renderer reads; joint reordering; infinities and NaN; errors that name the key.
#include "kinograph/planning/io/plan_json.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "tests/lib/temp_dir.h"
#include "tests/planning/test_problems.h"

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
  plan.stats.status = PlanStatus::kConverged;
  plan.stats.reason = "why not";
  plan.stats.iterations = 42;
  plan.stats.outer_iterations = 5;
  plan.stats.linear_solves = 84;
  plan.stats.attempts = 3;
  plan.stats.solve_time_s = 0.125;
  plan.stats.cost = 3.5;
  plan.stats.max_constraint_violation = 1.5e-5;
  plan.stats.times = {0.001, 0.002, 0.05, 0.025, 0.003, 0.004, 0.006, 0.007};
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
  const SolveTimes &x = a.stats.times, &y = b.stats.times;
  EXPECT_EQ(x.initialization_s, y.initialization_s);
  EXPECT_EQ(x.graph_building_s, y.graph_building_s);
  EXPECT_EQ(x.linearization_s, y.linearization_s);
  EXPECT_EQ(x.factorization_s, y.factorization_s);
  EXPECT_EQ(x.triangular_solve_s, y.triangular_solve_s);
  EXPECT_EQ(x.multipliers_s, y.multipliers_s);
  EXPECT_EQ(x.between_knot_checks_s, y.between_knot_checks_s);
  EXPECT_EQ(x.validation_s, y.validation_s);
  testing::expect_same_validation(a.validation, b.validation);
}

TEST(PlanJson, RoundTripsExactlyThroughAFile) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  const Plan plan = random_plan(scene.problem, 7);
  const kinograph::test_support::TempDir dir("kinograph_plan_json_test");
  const std::string path = (dir / "new" / "plan.json").string();
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
  // Infinite limits are null.
  EXPECT_TRUE(j["limits"]["effort"][0].is_null());
  EXPECT_EQ(j["limits"]["effort"][1], scene.problem.model->bodies[1].limits.effort);
  EXPECT_TRUE(j["limits"]["lower"][0].is_null());
  EXPECT_TRUE(j["validation"]["min_clearance"].is_null());
  EXPECT_TRUE(j["q"][2][1].is_null());
  // And back: null clearance is +inf, a null trajectory value NaN.
  const Plan back = plan_from_json(json::parse(j.dump()), *scene.problem.model);
  EXPECT_EQ(back.validation.min_clearance, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(back.q(2, 1)));
  EXPECT_EQ(back.q(2, 0), plan.q(2, 0));
  // Read whole, the robot gets the scene's limits back, the infinite ones included.
  const PlanFile file = plan_file_from_json(json::parse(j.dump()));
  EXPECT_EQ(file.model->bodies[0].limits.effort, std::numeric_limits<double>::infinity());
  EXPECT_EQ(file.model->bodies[0].limits.lower, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(file.model->bodies[1].limits.effort, scene.problem.model->bodies[1].limits.effort);
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
  EXPECT_NE(broken([](json& j) { j["stats"]["status"] = "fine"; }).find("stats.status"),
            std::string::npos);
  EXPECT_NE(broken([](json& j) { j["stats"]["times"] = 3; }).find("stats.times"),
            std::string::npos);
  EXPECT_NE(broken([](json& j) {
              j["stats"]["times"]["validation_s"] = "slow";
            }).find("stats.times.validation_s"),
            std::string::npos);
  EXPECT_THROW(read_plan("/no/such/plan.json", model), PlanFileError);
}

TEST(PlanStatus, NamesRoundTrip) {
  for (PlanStatus s : {PlanStatus::kConverged, PlanStatus::kInfeasible, PlanStatus::kNonFinite,
                       PlanStatus::kSingular, PlanStatus::kMaxUpdates, PlanStatus::kMaxRounds,
                       PlanStatus::kInvalidProblem, PlanStatus::kNoPlan, PlanStatus::kFailed}) {
    EXPECT_EQ(plan_status_from_string(to_string(s)), s) << to_string(s);
  }
  EXPECT_EQ(to_string(PlanStatus::kInvalidProblem), "invalid_problem");
  EXPECT_THROW(plan_status_from_string("max_iterations"), std::invalid_argument);
}

TEST(PlanFile, ReadsBackRobotObstaclesLimitsAndPlan) {
  const Scene scene = parse_scene(R"(robot:
  urdf: robots/iiwa14/iiwa14.urdf
  payload: {frame: iiwa_link_ee_kuka, mass: 1.5, size: [0.1, 0.1, 0.2], offset: [0, 0, 0.1]}
horizon: 2
steps: 10
start: {q: [0, 0, 0, 0, 0, 0, 0]}
goal: {q: [0.1, 0, 0, 0, 0, 0, 0]}
limits: {iiwa_joint_2: {velocity: 0.5, lower: -1}}
unactuated: [iiwa_joint_7]
obstacles:
  - {id: post, shape: cylinder, size: [0.1, 0.4], position: [0.5, 0, 0.2], rpy: [0.3, 0, 0]}
  - id: ball
    shape: sphere
    size: [0.2]
    motion: [{t: 0, position: [0, 0.5, 1]}, {t: 2, position: [1, 0.5, 1], rpy: [0, 0, 1]}]
)");
  const Plan plan = random_plan(scene.problem, 19);
  const kinograph::test_support::TempDir dir("kinograph_plan_file_test");
  const std::string path = (dir / "plan.json").string();
  write_plan(plan, scene, path);
  const PlanFile file = read_plan_file(path);
  expect_same_plan(plan, file.plan);
  const PlanFileInfo& info = file.info;
  EXPECT_EQ(info.source, path);
  EXPECT_EQ(info.urdf, "robots/iiwa14/iiwa14.urdf");
  ASSERT_TRUE(info.payload.has_value());
  EXPECT_EQ(info.payload->frame, "iiwa_link_ee_kuka");
  EXPECT_EQ(info.payload->mass, 1.5);
  EXPECT_EQ(info.payload->offset, Eigen::Vector3d(0, 0, 0.1));
  EXPECT_EQ(info.obstacle_names, (std::vector<std::string>{"post", "ball"}));
  ASSERT_EQ(info.obstacles.size(), 2u);
  ASSERT_EQ(info.obstacle_rgba.size(), 2u);
  EXPECT_FALSE(info.obstacle_rgba[0].has_value());
  for (std::size_t i = 0; i < 2; ++i) {
    const collision::Obstacle &a = scene.problem.obstacles[i], &b = info.obstacles[i];
    EXPECT_EQ(b.id, static_cast<int>(i));
    EXPECT_EQ(b.shape.kind, a.shape.kind);
    EXPECT_EQ(b.shape.size, a.shape.size);
    EXPECT_EQ(b.is_moving(), a.is_moving());
    for (double t : {-1.0, 0.0, 0.7, 1.5, 3.0}) {
      EXPECT_TRUE(b.pose_at(t).isApprox(a.pose_at(t), 1e-12)) << i << " at " << t;
    }
  }
  // The robot is the problem's: payload attached, the scene's limit overrides applied.
  const dynamics::Model& model = *file.model;
  const dynamics::Model& expected = *scene.problem.model;
  ASSERT_EQ(model.nq(), 7);
  EXPECT_EQ(model.visual.size(), expected.visual.size());
  for (int i = 0; i < 7; ++i) {
    const dynamics::JointLimits &l = model.bodies[i].limits, &e = expected.bodies[i].limits;
    EXPECT_EQ(l.lower, e.lower) << i;
    EXPECT_EQ(l.upper, e.upper) << i;
    EXPECT_EQ(l.velocity, e.velocity) << i;
    EXPECT_EQ(l.effort, e.effort) << i;
    EXPECT_EQ(model.bodies[i].actuated, expected.bodies[i].actuated) << i;
  }
  EXPECT_EQ(model.bodies[1].limits.velocity, 0.5);
  EXPECT_FALSE(model.bodies[6].actuated);
  EXPECT_EQ(info.limits.effort.size(), 7u);
}

TEST(PlanFile, InfiniteLimitsAndColoursAndColumnOrder) {
  const Scene scene = load_scene(kSceneDir + "rr_reach.yaml");
  json j = plan_to_json(random_plan(scene.problem, 2), scene);
  j["limits"]["effort"] = {nullptr, 4.0};
  j["limits"]["lower"] = {nullptr, -1.0};
  j["joint_names"] = {"joint2", "joint1"};  // limits follow the names, not the model's order
  j["obstacles"] = json::parse(R"([{"id": "a", "shape": "box", "size": [1, 2, 3],
                                    "rgba": [1, 0, 0, 0.5]}, {"size": [0.1, 0.2, 0.3]}])");
  const PlanFile file = plan_file_from_json(j, "p.json");
  EXPECT_EQ(file.model->bodies[0].limits.effort, 4.0);
  EXPECT_EQ(file.model->bodies[1].limits.effort, std::numeric_limits<double>::infinity());
  EXPECT_EQ(file.model->bodies[0].limits.lower, -1.0);
  EXPECT_EQ(file.model->bodies[1].limits.lower, -std::numeric_limits<double>::infinity());
  ASSERT_EQ(file.info.obstacles.size(), 2u);
  ASSERT_TRUE(file.info.obstacle_rgba[0].has_value());
  EXPECT_EQ(*file.info.obstacle_rgba[0], Eigen::Vector4d(1, 0, 0, 0.5));
  // Hand-written defaults: a box at the origin, named after its place in the list.
  EXPECT_EQ(file.info.obstacles[1].shape.kind, collision::ShapeKind::kBox);
  EXPECT_EQ(file.info.obstacle_names[1], "obstacles[1]");
  EXPECT_TRUE(file.info.obstacles[1].pose.isApprox(Eigen::Isometry3d::Identity()));
}

// The message of plan_file_from_json's error, which must name the plan and the key.
std::string file_error_of(const json& j) {
  try {
    plan_file_from_json(j, "p.json");
  } catch (const PlanFileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PlanFile, ErrorsNameTheKey) {
  const Scene scene = load_scene(kSceneDir + "iiwa_desk.yaml");
  const json good = plan_to_json(random_plan(scene.problem, 4), scene);
  ASSERT_EQ(file_error_of(good), "no error");
  const auto expect = [&](const char* needle, auto edit) {
    json j = good;
    edit(j);
    const std::string what = file_error_of(j);
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_NE(what.find("p.json"), std::string::npos) << what;
  };
  expect("'robot'", [](json& j) { j.erase("robot"); });
  expect("robots/no_such.urdf", [](json& j) { j["robot"]["urdf"] = "robots/no_such.urdf"; });
  expect("robot.payload", [](json& j) { j["robot"]["payload"]["frame"] = "no_frame"; });
  expect("robot.payload.size", [](json& j) { j["robot"]["payload"]["size"] = {1, 2}; });
  expect("torus", [](json& j) { j["obstacles"][1]["shape"] = "torus"; });
  expect("obstacles[2].size", [](json& j) { j["obstacles"][2]["size"] = {1, 2}; });
  expect("obstacles[0].quaternion", [](json& j) {
    j["obstacles"][0]["quaternion"] = {0, 0, 0, 0};
  });
  expect("obstacles[0].rgba", [](json& j) { j["obstacles"][0]["rgba"] = {1, 0}; });
  expect("gone.stl", [](json& j) {
    j["obstacles"][0] = {{"id", "m"}, {"shape", "mesh"}, {"mesh", "meshes/gone.stl"}};
  });
  expect("obstacles[3].motion[1].t", [](json& j) {
    j["obstacles"][3]["motion"] = json::parse(R"([{"t": 1, "position": [0, 0, 0]},
                                                  {"t": 1, "position": [0, 0, 1]}])");
  });
  expect("limits.effort", [](json& j) { j["limits"]["effort"] = {1, 2}; });
  expect("'q'", [](json& j) { j.erase("q"); });
  expect("iiwa_joint_3", [](json& j) { j["joint_names"][2] = "elbow"; });
  // Passive joints are named, never written as effort 0.
  expect("joint 'iiwa_joint_2' has effort limit 0", [](json& j) { j["limits"]["effort"][1] = 0; });
  expect("no joint 'elbow'", [](json& j) { j["unactuated"] = {"elbow"}; });
  expect("'unactuated'", [](json& j) { j["unactuated"] = "iiwa_joint_7"; });
  EXPECT_THROW(read_plan_file("/no/such/plan.json"), PlanFileError);
}

// A number no double holds is a PlanFileError naming the file, not nlohmann's bare
// out_of_range (number overflow parsing '1e309').
TEST(PlanFile, ANumberBeyondADoubleNamesTheFile) {
  const kinograph::test_support::TempDir dir("kinograph_plan_overflow_test");
  const std::string path = (dir / "huge.json").string();
  std::ofstream(path) << R"({"format_version": 1, "t": [0, 1e309]})";
  try {
    read_plan_file(path);
    ADD_FAILURE() << "no PlanFileError";
  } catch (const PlanFileError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1e309"), std::string::npos) << e.what();
  }
}

TEST(PlanFile, RelativePathsResolveNextToThePlan) {
  const kinograph::test_support::TempDir temp("kinograph_plan_path_test");
  const std::filesystem::path& dir = temp.path();
  std::ofstream(dir / "part.stl") << "solid x\nendsolid x\n";
  const std::string plan = (dir / "plan.json").string();
  EXPECT_EQ(resolve_plan_path("part.stl", plan),
            std::filesystem::canonical(dir / "part.stl").string());
  EXPECT_EQ(
      resolve_plan_path("robots/rr/rr.urdf", plan),
      std::filesystem::canonical(std::filesystem::path(KINOGRAPH_SOURCE_DIR) / "robots/rr/rr.urdf")
          .string());
  EXPECT_FALSE(resolve_plan_path("no_such_part.stl", plan).has_value());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace kinograph::planning
