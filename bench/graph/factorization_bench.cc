// EnvelopeCholesky on the normal equations of a trajectory graph in time order: states of
// `--state` variables, each coupled to the state before (a block band two states wide, as the
// condensed iiwa plan's H). Prints the median time of one factorization and of one solve, a
// Markdown table and, with --json, the figures.
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "kinograph/graph/envelope_cholesky.h"

namespace kinograph::bench {
namespace {

using Clock = std::chrono::steady_clock;

int run(int argc, char** argv) {
  int states = 31, state = 21, reps = 15, inner = 200;
  std::string json_path;
  if (!Flags("factorization_bench")
           .value("--states", &states)
           .value("--state", &state)
           .value("--reps", &reps)
           .value("--inner", &inner)
           .value("--json", &json_path)
           .parse(argc, argv)) {
    return 64;
  }
  if (states < 1 || state < 1 || reps < 1 || inner < 1) {
    std::cerr << "factorization_bench: every count must be at least 1\n";
    return 64;
  }
  const int n = states * state;
  std::vector<int> col_ptr{0}, row_idx;
  std::vector<double> values;
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  for (int j = 0; j < n; ++j) {
    for (int i = std::max(0, (j / state - 1) * state); i <= j; ++i) {
      row_idx.push_back(i);
      values.push_back(i == j ? 4.0 * state : normal(rng));  // diagonally dominant: SPD
    }
    col_ptr.push_back(static_cast<int>(row_idx.size()));
  }
  graph::EnvelopeCholesky chol(n, col_ptr, row_idx);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
  Eigen::VectorXd x(n);
  std::vector<double> factor_us, solve_us;
  for (int r = 0; r < reps; ++r) {
    auto t0 = Clock::now();
    for (int k = 0; k < inner; ++k) {
      std::copy(values.begin(), values.end(), chol.values());
      if (!chol.factorize()) {
        std::cerr << "factorization_bench: the matrix is not positive definite\n";
        return 1;
      }
    }
    factor_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() /
                        inner);
    t0 = Clock::now();
    for (int k = 0; k < inner; ++k) chol.solve(b, x);
    solve_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() /
                       inner);
  }
  const double flops = graph::EnvelopeCholesky::flops(n, col_ptr, row_idx);
  const nlohmann::json out = {{"states", states},
                              {"state", state},
                              {"n", n},
                              {"multiply_adds", flops},
                              {"factorize_us_median", median(factor_us)},
                              {"solve_us_median", median(solve_us)},
                              {"reps", reps},
                              {"inner", inner}};
  std::cout << std::fixed << std::setprecision(1)
            << "| n | multiply-adds | factorize (µs) | solve (µs) |\n|---|---|---|---|\n| " << n
            << " | " << std::setprecision(0) << flops << " | " << std::setprecision(1)
            << median(factor_us) << " | " << median(solve_us) << " |\n";
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return 0;
}

}  // namespace
}  // namespace kinograph::bench

int main(int argc, char** argv) { return kinograph::bench::run(argc, argv); }
