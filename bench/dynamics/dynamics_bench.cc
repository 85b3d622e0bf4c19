// Dynamics microbenchmarks: on the iiwa14 RNEA, RNEA with all derivatives, mass matrix,
// forward dynamics, forward kinematics; on the Acrobot the passive-joint dynamics of the
// shooting rows. Run with
//   bench_dynamics --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
//                  --benchmark_out=dynamics.json --benchmark_out_format=json
// The console shows Google Benchmark's usual output followed by a Markdown table of medians
// (real and CPU time; on a shared machine real time includes waiting for a core).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/inverse_dynamics.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/dynamics/model.h"
#include "kinograph/dynamics/payload.h"

namespace kd = kinograph::dynamics;

namespace {

struct Fixture {
  kd::Model model =
      kd::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/iiwa14/iiwa14.urdf");
  kd::Data data{model};
  Eigen::VectorXd q, qd, qdd;
  Fixture() {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    q.resize(7);
    qd.resize(7);
    qdd.resize(7);
    for (int i = 0; i < 7; ++i) {
      q[i] = 2.0 * u(rng);
      qd[i] = u(rng);
      qdd[i] = 3.0 * u(rng);
    }
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_Rnea(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    benchmark::DoNotOptimize(kd::rnea(f.model, f.data, f.q, f.qd, f.qdd).data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_Rnea);

void BM_RneaDerivatives(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    kd::rnea_derivatives(f.model, f.data, f.q, f.qd, f.qdd);
    benchmark::DoNotOptimize(f.data.dtau_dq.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_RneaDerivatives);

void BM_MassMatrix(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    benchmark::DoNotOptimize(kd::mass_matrix(f.model, f.data, f.q).data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_MassMatrix);

void BM_ForwardDynamics(benchmark::State& state) {
  Fixture& f = fixture();
  const Eigen::VectorXd tau = kd::rnea(f.model, f.data, f.q, f.qd, f.qdd);
  for (auto _ : state) {
    benchmark::DoNotOptimize(kd::forward_dynamics(f.model, f.data, f.q, f.qd, tau).data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ForwardDynamics);

void BM_ForwardKinematics(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) {
    kd::forward_kinematics(f.model, f.data, f.q);
    benchmark::DoNotOptimize(f.data.body_pose.back().data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ForwardKinematics);

// The Acrobot with its shoulder passive: one RK4 stage of the planner's shooting rows, with and
// without the derivatives its sensitivities need.
struct AcrobotFixture {
  kd::Model model =
      kd::Model::from_urdf_file(std::string(KINOGRAPH_SOURCE_DIR) + "/robots/acrobot/acrobot.urdf");
  kd::Data data{model};
  Eigen::Vector2d q{0.7, -1.3}, qd{1.1, 2.4}, qdd{0.0, 3.0};
  std::vector<int> passive{0};
};

void BM_AcrobotPassiveDynamics(benchmark::State& state) {
  static AcrobotFixture f;
  const bool derivatives = state.range(0) != 0;
  for (auto _ : state) {
    kd::passive_dynamics(f.model, f.data, f.q, f.qd, f.qdd, f.passive, derivatives);
    benchmark::DoNotOptimize(f.data.qdd.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_AcrobotPassiveDynamics)->Arg(0)->Arg(1);

// Console output as usual, plus a Markdown table of the median (or single-run) times.
class MarkdownReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const bool single = r.run_type == Run::RT_Iteration && r.repetitions <= 1;
      if (single || r.aggregate_name == "median") {
        rows_.push_back({r.run_name.function_name, r.GetAdjustedRealTime(), r.GetAdjustedCPUTime(),
                         benchmark::GetTimeUnitString(r.time_unit)});
      }
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\n| benchmark (iiwa14; Acrobot: AcrobotPassiveDynamics, /1 with derivatives) | median real time | median CPU time |\n|---|---|---|\n");
    for (const Row& r : rows_) {
      std::printf("| %s | %.0f %s | %.0f %s |\n", r.name.c_str(), r.real, r.unit, r.cpu, r.unit);
    }
  }

 private:
  struct Row {
    std::string name;
    double real, cpu;
    const char* unit;
  };
  std::vector<Row> rows_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  MarkdownReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
