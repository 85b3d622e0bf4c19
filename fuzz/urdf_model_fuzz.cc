// Fuzz target: the URDF loader path (urdf_outline's strict first pass, urdfdom, the model
// building), with relative mesh paths resolved against robots/. Findings: a crash (the XML
// parser's recursion on deep nesting among them), a hang, a sanitizer report, or an exception
// other than UrdfError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_data.h"
#include "kinograph/dynamics/urdf_error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kinograph;
  static const std::string base_dir = fuzz::source_path("robots");
  try {
    const dynamics::Model model = dynamics::Model::from_urdf_string(
        std::string(reinterpret_cast<const char*>(data), size), base_dir);
    (void)model.total_mass();
  } catch (const dynamics::UrdfError& e) {
    fuzz::expect_names(e.what(), "<urdf string>");
  }
  return 0;
}
