// `kinograph export PLAN.json --csv plan.csv`: a plan's trajectory as CSV for spreadsheets and
// plotting tools: one row per state, columns t, then q, qd, qdd and tau per joint.
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "kinograph/planning/io/plan_json.h"
#include "tools/command_registry.h"

namespace kinograph::tools {
namespace {

struct ExportArgs {
  std::string plan;
  std::string csv;
};

// Enough digits to read back the same double.
std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

void run_export(const ExportArgs& args) {
  planning::PlanFile file;
  try {
    file = planning::read_plan_file(args.plan);
  } catch (const std::exception& e) {
    throw CommandFailure(e.what());
  }
  const planning::Plan& plan = file.plan;
  std::ofstream out(args.csv);
  if (!out) throw CommandFailure("cannot write '" + args.csv + "'");
  out << "t";
  for (const char* quantity : {"q", "qd", "qdd", "tau"}) {
    for (const dynamics::Body& body : file.model->bodies)
      out << "," << quantity << ":" << body.joint_name;
  }
  out << "\n";
  for (std::size_t k = 0; k < plan.t.size(); ++k) {
    out << number(plan.t[k]);
    for (const Eigen::MatrixXd* m : {&plan.q, &plan.qd, &plan.qdd, &plan.tau}) {
      for (Eigen::Index j = 0; j < m->cols(); ++j) out << "," << number((*m)(k, j));
    }
    out << "\n";
  }
  if (!out) throw CommandFailure("cannot write '" + args.csv + "'");
}

const bool kExportRegistered = register_command([](CLI::App& root) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = root.add_subcommand(
      "export", "Write a plan's trajectory as CSV: t, then q, qd, qdd and tau of every joint");
  cmd->add_option("plan", args->plan, "Plan file (JSON)")->required();
  cmd->add_option("--csv", args->csv,
                  "CSV file to write, one row per state: t (s), q:<joint> (rad or m), "
                  "qd:<joint> (rad/s or m/s), qdd:<joint> (rad/s² or m/s²), tau:<joint> "
                  "(N·m or N)")
      ->required();
  cmd->callback([args] { run_export(*args); });
});

}  // namespace
}  // namespace kinograph::tools
