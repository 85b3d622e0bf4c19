// The CLI's planning verbs plan in the formulation asked for (--formulation, else the scene's
// planner.formulation), print it and record it in their plan files. The plan itself tells the
// two apart: the DFG's torques are its own τ variables, which meet the equations of motion only
// to the solver's tolerance, while the condensed torques are RNEA of the trajectory itself.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "kinograph/planning/io/scene.h"
#include "tests/lib/temp_dir.h"
#include "tests/tools/cli_run.h"

namespace kinograph::tools {
namespace {

namespace fs = std::filesystem;

// A dynamics residual above this is not rounding: the plan's τ are not RNEA of its trajectory.
constexpr double kRoundoff = 1e-9;

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::string repo(const std::string& path) { return std::string(KINOGRAPH_SOURCE_DIR) + "/" + path; }

class CliFormulation : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test_support::TempDir::make(
        std::string("kinograph_cli_formulation_") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    // rr_reach with planner.formulation: dfg (paths written resolved, so it reads anywhere).
    planning::Scene scene = planning::load_scene(repo("robots/scenes/rr_reach.yaml"));
    ASSERT_EQ(scene.planner.formulation, "condensed");
    scene.planner.formulation = "dfg";
    dfg_scene_ = (dir_ / "rr_reach_dfg.yaml").string();
    std::ofstream(dfg_scene_) << planning::scene_to_yaml(scene);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Plans `scene` with `flags`; returns the plan file, after checking that the output names
  // `formulation`.
  nlohmann::json plan(const std::string& scene, const std::string& flags,
                      const std::string& formulation) {
    const fs::path out = dir_ / "plan.json";
    const CliRun r = run_cli("plan " + scene + " " + flags + " --out " + out.string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("formulation: " + formulation + "\n"), std::string::npos) << r.output;
    return read_json(out);
  }

  fs::path dir_;
  std::string dfg_scene_;
};

TEST_F(CliFormulation, PlanFlagSelectsTheFullDynamicFactorGraph) {
  const nlohmann::json dfg = plan(repo("robots/scenes/rr_reach.yaml"), "--formulation dfg", "dfg");
  EXPECT_EQ(dfg["stats"]["formulation"], "dfg");
  EXPECT_TRUE(dfg["validation"]["valid"].get<bool>());
  EXPECT_GT(dfg["validation"]["max_dynamics_residual"].get<double>(), kRoundoff);

  const nlohmann::json condensed =
      plan(repo("robots/scenes/rr_reach.yaml"), "--formulation condensed", "condensed");
  EXPECT_EQ(condensed["stats"]["formulation"], "condensed");
  EXPECT_LT(condensed["validation"]["max_dynamics_residual"].get<double>(), kRoundoff);
}

TEST_F(CliFormulation, PlanTakesTheScenesFormulationUnlessTheFlagOverridesIt) {
  const nlohmann::json from_scene = plan(dfg_scene_, "", "dfg");
  EXPECT_EQ(from_scene["stats"]["formulation"], "dfg");
  EXPECT_GT(from_scene["validation"]["max_dynamics_residual"].get<double>(), kRoundoff);

  const nlohmann::json overridden = plan(dfg_scene_, "--formulation condensed", "condensed");
  EXPECT_EQ(overridden["stats"]["formulation"], "condensed");
  EXPECT_LT(overridden["validation"]["max_dynamics_residual"].get<double>(), kRoundoff);

  const nlohmann::json by_default = plan(repo("robots/scenes/rr_reach.yaml"), "", "condensed");
  EXPECT_EQ(by_default["stats"]["formulation"], "condensed");
}

TEST_F(CliFormulation, ReplanPlansInTheFormulationOfTheFlagOrTheScene) {
  const std::string change = repo("robots/scenes/changes/rr_reach_goal.yaml");
  const fs::path before = dir_ / "before.json", after = dir_ / "after.json";
  const auto replan = [&](const std::string& scene, const std::string& flags,
                          const std::string& formulation) {
    const CliRun r = run_cli("replan " + scene + " " + change + " " + flags + " --out-before " +
                             before.string() + " --out-after " + after.string());
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("formulation: " + formulation + "\n"), std::string::npos) << r.output;
    EXPECT_EQ(read_json(before)["stats"]["formulation"], formulation);
    EXPECT_EQ(read_json(after)["stats"]["formulation"], formulation);
  };
  replan(repo("robots/scenes/rr_reach.yaml"), "--formulation dfg", "dfg");
  replan(dfg_scene_, "", "dfg");
  replan(dfg_scene_, "--formulation condensed", "condensed");
  replan(repo("robots/scenes/rr_reach.yaml"), "", "condensed");
}

TEST_F(CliFormulation, AnUnknownFormulationIsABadFlag) {
  const CliRun r = run_cli("plan " + repo("robots/scenes/rr_reach.yaml") +
                           " --formulation fast --out " + (dir_ / "plan.json").string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.output.find("formulation"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "plan.json"));
}

}  // namespace
}  // namespace kinograph::tools
