// Plan file versions: files are written with format_version, a file written before the field
// existed (committed, by kinograph 0.1.0) still reads whole, and a newer or malformed version is
// refused with a message naming the file, the key and the version.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "kinograph/planning/io/plan_json.h"
#include "tests/lib/temp_dir.h"

namespace kinograph::planning {
namespace {

using nlohmann::json;

const std::string kSource = KINOGRAPH_SOURCE_DIR;
// `kinograph plan robots/scenes/rr_reach.yaml` at commit 20a9d03, before format_version.
const std::string kUnversioned = kSource + "/tests/planning/data/plan_unversioned_rr_reach.json";

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// Writes `j` to a file of this test's own directory and returns its path.
std::string write_json(const json& j, const std::string& name) {
  static const kinograph::test_support::TempDir dir("kinograph_plan_version_test");
  const std::string path = (dir / name).string();
  std::ofstream(path) << j.dump(1);
  return path;
}

// What read_plan_file (or, with a model, read_plan) throws for the file `path`.
std::string error_of(const std::string& path, const dynamics::Model* model = nullptr) {
  try {
    model ? (void)read_plan(path, *model) : (void)read_plan_file(path);
  } catch (const PlanFileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(PlanFileVersion, WrittenFilesCarryTheCurrentVersion) {
  const Scene scene = load_scene(kSource + "/robots/scenes/rr_reach.yaml");
  const PlanFile old = read_plan_file(kUnversioned);
  const json j = plan_to_json(old.plan, scene);
  ASSERT_TRUE(j.contains("format_version"));
  EXPECT_EQ(j["format_version"], kPlanFormatVersion);
  EXPECT_EQ(plan_format_version(j), kPlanFormatVersion);
}

TEST(PlanFileVersion, UnversionedFileReadsWhole) {
  const json j = read_json(kUnversioned);
  ASSERT_FALSE(j.contains("format_version")) << "the committed file must predate the field";
  EXPECT_EQ(plan_format_version(j, kUnversioned), 0);
  const PlanFile file = read_plan_file(kUnversioned);
  EXPECT_EQ(file.info.name, "rr_reach");
  EXPECT_EQ(file.info.joint_names, (std::vector<std::string>{"joint1", "joint2"}));
  ASSERT_EQ(file.info.obstacle_names, std::vector<std::string>{"ball"});
  EXPECT_EQ(file.model->nq(), 2);
  // rr_reach.yaml: 30 steps over 3 s from (-1.2, 0) to (1.2, 0), validated.
  ASSERT_EQ(file.plan.t.size(), 31u);
  EXPECT_DOUBLE_EQ(file.plan.t.back(), 3.0);
  EXPECT_NEAR(file.plan.q(0, 0), -1.2, 1e-12);
  EXPECT_NEAR(file.plan.q(30, 0), 1.2, 1e-6);
  EXPECT_NEAR(file.plan.q(30, 1), 0.0, 1e-6);
  EXPECT_TRUE(file.plan.validation.valid);
  EXPECT_EQ(file.plan.stats.iterations, 24);
  // The same trajectory through the model-only reader (validate, warm starts).
  const Plan plan = read_plan(kUnversioned, *file.model);
  EXPECT_EQ(plan.q, file.plan.q);
  EXPECT_EQ(plan.tau, file.plan.tau);
}

TEST(PlanFileVersion, RewrittenOldFileRoundTrips) {
  const Scene scene = load_scene(kSource + "/robots/scenes/rr_reach.yaml");
  const PlanFile old = read_plan_file(kUnversioned);
  const std::string path = write_json(plan_to_json(old.plan, scene), "rewritten.json");
  const PlanFile back = read_plan_file(path);
  EXPECT_EQ(plan_format_version(read_json(path)), kPlanFormatVersion);
  EXPECT_EQ(back.plan.t, old.plan.t);
  EXPECT_EQ(back.plan.q, old.plan.q);
  EXPECT_EQ(back.plan.qd, old.plan.qd);
  EXPECT_EQ(back.plan.qdd, old.plan.qdd);
  EXPECT_EQ(back.plan.tau, old.plan.tau);
}

TEST(PlanFileVersion, NewerVersionIsRefusedNamingFileAndVersion) {
  json j = read_json(kUnversioned);
  j["format_version"] = kPlanFormatVersion + 1;
  const std::string path = write_json(j, "newer.json");
  const PlanFile old = read_plan_file(kUnversioned);
  for (const dynamics::Model* model :
       {static_cast<const dynamics::Model*>(nullptr), old.model.get()}) {
    const std::string what = error_of(path, model);
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("'format_version': is " + std::to_string(kPlanFormatVersion + 1)),
              std::string::npos)
        << what;
    EXPECT_NE(what.find("newer than this kinograph reads"), std::string::npos) << what;
  }
}

TEST(PlanFileVersion, MalformedVersionIsRefused) {
  json j = read_json(kUnversioned);
  for (const json& bad : {json("1"), json(0), json(-3), json(1.5), json(nullptr)}) {
    j["format_version"] = bad;
    const std::string path = write_json(j, "malformed.json");
    const std::string what = error_of(path);
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("'format_version': must be an integer >= 1, is " + bad.dump()),
              std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace kinograph::planning
