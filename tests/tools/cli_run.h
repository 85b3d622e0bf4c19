#pragma once
// Runs the real `kinograph` binary (KINOGRAPH_CLI) and collects its exit status and output.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace kinograph::tools {

/// What one run of the CLI did: its exit code (-1 if it did not exit) and stdout + stderr.
struct CliRun {
  int status = -1;
  std::string output;
};

/// Runs `kinograph <args>` through the shell, stderr merged into the output.
inline CliRun run_cli(const std::string& args) {
  const std::string command = std::string(KINOGRAPH_CLI) + " " + args + " 2>&1";
  CliRun result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 512> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int raw = pclose(pipe);
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return result;
}

}  // namespace kinograph::tools
