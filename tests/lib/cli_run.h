#pragma once
// Runs a shell command (a CLI under test) and collects its exit status and its output, stdout
// and stderr together, for tests of the real binaries.
#include <array>
#include <cstdio>
#include <string>

namespace kinograph::testing {

/// Exit status (as pclose returns it) and combined output of one command.
struct CliRun {
  int status = -1;
  std::string output;
};

/// Runs `command` through the shell with stderr joined to stdout.
inline CliRun run_command(const std::string& command) {
  CliRun result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 512> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  result.status = pclose(pipe);
  return result;
}

}  // namespace kinograph::testing
