// The `kinograph` command-line tool: dispatches to the verbs in cmd_*.cc.
#include <spdlog/spdlog.h>

#include <iostream>

#include "tools/command_registry.h"

namespace kinograph::tools {

std::vector<CommandSetup>& command_registry() {
  static std::vector<CommandSetup> registry;
  return registry;
}

bool register_command(CommandSetup setup) {
  command_registry().push_back(std::move(setup));
  return true;
}

}  // namespace kinograph::tools

int main(int argc, char** argv) {
  CLI::App app{"kinograph: kinodynamic motion planning on dynamic factor graphs"};
  app.require_subcommand(1);
  // Library messages (solver progress, per-update timing at debug) go to stderr via spdlog.
  app.add_option_function<std::string>(
         "--log-level",
         [](const std::string& level) { spdlog::set_level(spdlog::level::from_str(level)); },
         "Library log level: trace, debug, info, warn (default), error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  spdlog::set_level(spdlog::level::warn);
  for (const auto& setup : kinograph::tools::command_registry()) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const kinograph::tools::CommandFailure& e) {
    // An empty message means the verb already printed why (e.g. a plan that did not validate).
    if (std::string(e.what()).size() > 0) std::cerr << "kinograph: error: " << e.what() << "\n";
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "kinograph: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
