#include "fuzz/fuzz_data.h"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>

namespace kinograph::fuzz {
namespace {

// The readers' warnings (an unknown effort, an undefined material) say nothing a finding needs
// and would cost most of each run's time.
[[maybe_unused]] const bool kQuiet = (spdlog::set_level(spdlog::level::off), true);

}  // namespace

void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
  std::abort();
}

void expect_names(const std::string& message, const std::string& source) {
  if (message.find(source) == std::string::npos) {
    fail("an error that does not name its file '" + source + "': " + message);
  }
}

}  // namespace kinograph::fuzz
