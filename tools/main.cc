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

const char* exit_code_table() {
  return "Exit codes:\n"
         "  0   done (a plan validates)\n"
         "  1   bad input: a file, robot, scene, plan, message or value is wrong\n"
         "  2   a plan was made or received but does not validate\n"
         "  3   no answer within --wait\n"
         "  64  usage: unknown verb or option, missing or malformed argument\n";
}

}  // namespace kinograph::tools

int main(int argc, char** argv) {
  namespace kt = kinograph::tools;
  CLI::App app{"kinograph: kinodynamic motion planning on dynamic factor graphs"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "kinograph " KINOGRAPH_VERSION);
  app.footer(kt::exit_code_table());
  // Inherited by every verb: global options (--log-level) are accepted after the verb too.
  app.fallthrough();
  // Library messages (solver progress, per-update timing at debug) go to stderr via spdlog.
  app.add_option_function<std::string>(
         "--log-level",
         [](const std::string& level) { spdlog::set_level(spdlog::level::from_str(level)); },
         "Library log level: trace, debug, info, warn (default), error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  spdlog::set_level(spdlog::level::warn);
  for (const auto& setup : kt::command_registry()) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const kt::CommandFailure& e) {
    // An empty message means the verb already printed why (e.g. a plan that did not validate).
    if (std::string(e.what()).size() > 0) std::cerr << "kinograph: error: " << e.what() << "\n";
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    // --help and --version end here with code 0; every real usage error gets one code.
    const int code = app.exit(e);
    return code == 0 ? kt::kExitOk : kt::kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "kinograph: error: " << e.what() << "\n";
    return kt::kExitBadInput;
  }
  return kt::kExitOk;
}
