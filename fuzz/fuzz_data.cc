#include "fuzz/fuzz_data.h"

#include <cstdio>
#include <cstdlib>

namespace kinograph::fuzz {

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
