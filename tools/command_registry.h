#pragma once
// Verbs of the `kinograph` CLI register themselves here, one file per verb (cmd_<verb>.cc),
// so adding a verb never touches main.cc.
#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace kinograph::tools {

/// Adds one subcommand (with its options and callback) to the root app.
using CommandSetup = std::function<void(CLI::App& root)>;

/// All registered verbs, in registration order.
std::vector<CommandSetup>& command_registry();

/// Registers a verb; use as `const bool kVerbRegistered = register_command(...)` in an unnamed
/// namespace, a name of its own per file: files of a target are compiled together (unity build).
bool register_command(CommandSetup setup);

/// Exit codes of every verb (the table in `kinograph --help` and the README).
inline constexpr int kExitOk = 0;           ///< done; a plan validates
inline constexpr int kExitBadInput = 1;     ///< a file, robot, scene, message or value is wrong
inline constexpr int kExitInvalidPlan = 2;  ///< a plan was made or received but is not valid
inline constexpr int kExitTimeout = 3;      ///< no answer within --wait
/// The command line itself is wrong: unknown verb or option, missing or malformed argument.
inline constexpr int kExitUsage = 64;

/// The exit-code table as printed at the end of `kinograph --help`.
const char* exit_code_table();

/// Thrown by a verb's callback to end the CLI with a message and a non-zero exit code.
struct CommandFailure : CLI::RuntimeError {
  explicit CommandFailure(const std::string& message, int exit_code = kExitBadInput)
      : CLI::RuntimeError(message, exit_code) {}
};

}  // namespace kinograph::tools
