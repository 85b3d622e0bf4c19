// Fuzz target: the plan-file reader as `kinograph validate` and the renderer use it. The bytes
// are written to a file next to nothing else and read both ways: for the RR arm of
// robots/scenes/rr_reach.yaml (then validated against that scene) and whole (the robot the file
// names). Findings: a crash, a hang (validate's walk included), a sanitizer report, or an
// exception other than PlanFileError (or one not naming the file).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "fuzz/fuzz_data.h"
#include "kinograph/planning/io/plan_json.h"
#include "kinograph/planning/validate.h"

namespace {

// One scratch file per process, in a directory of its own (removed at exit).
class ScratchFile {
 public:
  ScratchFile() {
    char dir[] = "/tmp/kinograph-fuzz-plan-XXXXXX";
    if (mkdtemp(dir) == nullptr) kinograph::fuzz::fail("cannot create a temporary directory");
    dir_ = dir;
    path_ = dir_ + "/plan.json";
  }
  ~ScratchFile() {
    std::remove(path_.c_str());
    rmdir(dir_.c_str());
  }
  const std::string& write(const uint8_t* data, size_t size) {
    FILE* f = std::fopen(path_.c_str(), "wb");
    if (f == nullptr || std::fwrite(data, 1, size, f) != size || std::fclose(f) != 0) {
      kinograph::fuzz::fail("cannot write " + path_);
    }
    return path_;
  }

 private:
  std::string dir_, path_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kinograph;
  fuzz::read_each_urdf_once();
  static ScratchFile scratch;
  static const bool data_dir = (fuzz::use_source_data_dir(), true);
  (void)data_dir;
  static const planning::Scene scene =
      planning::load_scene(fuzz::source_path("robots/scenes/rr_reach.yaml"));
  const std::string& path = scratch.write(data, size);
  // Parsed once and read both ways, as read_plan and read_plan_file would each read it.
  nlohmann::json parsed;
  try {
    parsed = planning::read_plan_json(path);
  } catch (const planning::PlanFileError& e) {
    fuzz::expect_names(e.what(), path);
    return 0;
  }
  try {
    const planning::Plan plan = planning::plan_from_json(parsed, *scene.problem.model, path);
    (void)planning::validate(scene.problem, plan);
  } catch (const planning::PlanFileError& e) {
    fuzz::expect_names(e.what(), path);
  }
  try {
    (void)planning::plan_file_from_json(parsed, path);
  } catch (const planning::PlanFileError& e) {
    fuzz::expect_names(e.what(), path);
  }
  return 0;
}
