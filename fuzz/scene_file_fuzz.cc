// Fuzz target: the scene-file parser as `kinograph plan` uses it. The bytes are a scene read as
// robots/scenes/fuzz.yaml (so the shipped robots resolve); an accepted scene must write back
// to YAML that parses again, and the planner's pre-solve check and straight-line guess must
// not fail on it. Findings: a crash, a hang, a sanitizer report, an exception other than
// SceneError (or one not naming the file), or a written scene that does not read back.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_data.h"
#include "kinograph/planning/formulation/initialization.h"
#include "kinograph/planning/io/scene.h"
#include "kinograph/planning/problem_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kinograph;
  fuzz::read_each_urdf_once();
  static const std::string source = fuzz::source_path("robots/scenes/fuzz.yaml");
  planning::Scene scene;
  try {
    scene = planning::parse_scene(std::string(reinterpret_cast<const char*>(data), size), source);
  } catch (const planning::SceneError& e) {
    fuzz::expect_names(e.what(), source);
    return 0;
  }
  try {
    (void)planning::parse_scene(planning::scene_to_yaml(scene), source);
  } catch (const planning::SceneError& e) {
    fuzz::fail(std::string("an accepted scene does not read back: ") + e.what());
  }
  if (planning::check_problem(scene.problem).empty() &&
      scene.problem.goal.kind == planning::Goal::Kind::kJoint) {
    (void)planning::straight_line(scene.problem, scene.problem.goal.q);
  }
  return 0;
}
