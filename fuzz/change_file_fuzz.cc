// Fuzz target: the change-file reader of `kinograph replan`, for the RR arm's and the iiwa's
// shipped scenes (the corpus holds changes for both). An accepted change is applied, and the
// changed problem goes through the planner's pre-solve check. Findings: a crash, a hang, a
// sanitizer report, or an exception other than SceneError (or one not naming the file).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_data.h"
#include "kinograph/planning/io/replan_change.h"
#include "kinograph/planning/problem_check.h"

namespace {

// parse_change for `scene`, whose reader writes the scene out once per process, not per input.
void try_change(const std::string& text, const kinograph::planning::Scene& scene,
                const kinograph::planning::ChangeReader& reader) {
  using namespace kinograph;
  static const std::string source = fuzz::source_path("robots/scenes/changes/fuzz.yaml");
  planning::SceneChange change;
  try {
    change = reader.parse(text, source);
  } catch (const planning::SceneError& e) {
    fuzz::expect_names(e.what(), source);
    return;
  }
  (void)planning::check_problem(planning::apply_change(scene, change).problem);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kinograph;
  fuzz::read_each_urdf_once();
  static const planning::Scene rr =
      planning::load_scene(fuzz::source_path("robots/scenes/rr_reach.yaml"));
  static const planning::Scene iiwa =
      planning::load_scene(fuzz::source_path("robots/scenes/iiwa_desk.yaml"));
  static const planning::ChangeReader rr_reader(rr), iiwa_reader(iiwa);
  const std::string text(reinterpret_cast<const char*>(data), size);
  try_change(text, rr, rr_reader);
  try_change(text, iiwa, iiwa_reader);
  return 0;
}
