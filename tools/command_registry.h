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

/// Registers a verb; use as `static const bool kRegistered = register_command(...)`.
bool register_command(CommandSetup setup);

/// Thrown by a verb's callback to end the CLI with a message and a non-zero exit code.
struct CommandFailure : CLI::RuntimeError {
  explicit CommandFailure(const std::string& message, int exit_code = 1)
      : CLI::RuntimeError(message, exit_code) {}
};

}  // namespace kinograph::tools
