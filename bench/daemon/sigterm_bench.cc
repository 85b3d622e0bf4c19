// sigterm_bench: how soon kinographd answers and exits after SIGTERM while it plans. Each trial
// starts a daemon, sends it one goal whose plan takes seconds, waits until its heartbeat says
// PLANNING, waits a further spread delay (so that signals land at different points of the
// solve), sends SIGTERM and times the CANCELLED plan_t and the exit (pidfd, no polling).
// A trial whose plan ended before the signal is run again. Prints JSON and a Markdown table.
//   sigterm_bench --daemon kinographd --scene SLOW.yaml --url udpm://... [--trials 20]
//                 [--q 0.771,...] [--spread-ms 400] [--logs DIR] [--json FILE]
//                 [--daemon-arg ARG ...]
// Run it in a private network namespace (bench/daemon/sigterm_bench.sh does). The daemon runs at
// niceness 0 even when this observer runs at a lower one (so that its timestamps are taken when
// the events happen, not when a loaded machine gets round to it).
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/common/bench_flags.h"
#include "bench/common/bench_stats.h"
#include "kinograph/goal_t.hpp"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "lcmtypes/safe_decode.h"

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;
constexpr char kPrefix[] = "SIGB";

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

std::vector<double> parse_list(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) v.push_back(std::stod(item));
  return v;
}

// What the daemon under test sent: its newest heartbeat and the answer to the goal.
struct Listener {
  std::optional<kinograph::planner_status_t> status;
  std::optional<kinograph::plan_t> answer;
  Clock::time_point answer_at;
  int64_t goal_id = -1;
  // When poll() returned: an answer and the exit seen by one wake-up get the same time.
  std::optional<Clock::time_point> woken;

  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    kinograph::planner_status_t s;
    if (kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), s).ok) {
      status = s;
    }
  }
  void on_plan(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto now = woken.value_or(Clock::now());
    kinograph::plan_t p;
    if (!kinograph::lcmtypes::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), p).ok ||
        p.goal_id != goal_id || answer) {
      return;
    }
    answer = p;
    answer_at = now;
  }
};

// Handles LCM until `done` says so or `timeout_s` passes; false on the timeout.
template <class Done>
bool handle_until(lcm::LCM& lcm, double timeout_s, Done done) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(timeout_s));
  while (!done()) {
    if (Clock::now() >= end) return false;
    lcm.handleTimeout(5);
  }
  return true;
}

pid_t spawn_daemon(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error("cannot start " + args[0]);
  return pid;
}

// One trial's figures; nullopt when the plan ended before the signal.
struct Trial {
  double delay_ms = 0;   // from the PLANNING heartbeat to the signal
  double answer_ms = 0;  // signal to the CANCELLED plan_t (NaN: none)
  double exit_ms = 0;    // signal to the daemon's exit
  int exit_code = -1;
  std::string status_message;
  std::string daemon_says;  // the daemon's own "every goal answered N ms after it"
};

}  // namespace

int main(int argc, char** argv) {
  std::string daemon, scene, url, json_path, logs = "/tmp";
  std::string q_text = "0.771,0.335,-0.570,-1.046,-0.686,0.356,-0.122";
  std::vector<std::string> daemon_args;
  int trials = 20;
  double spread_ms = 400;
  kinograph::bench::Flags flags("sigterm_bench");
  flags.value("--daemon", &daemon).value("--scene", &scene).value("--url", &url)
      .value("--trials", &trials).value("--q", &q_text).value("--spread-ms", &spread_ms)
      .value("--logs", &logs).value("--json", &json_path)
      .value("--daemon-arg", "ARG", [&](const std::string& a) { daemon_args.push_back(a); });
  if (!flags.parse(argc, argv) || daemon.empty() || scene.empty() || url.empty()) {
    std::cerr << "sigterm_bench: --daemon, --scene and --url are required\n";
    return 2;
  }
  const std::vector<double> goal_q = parse_list(q_text);
  errno = 0;
  const int own_nice = getpriority(PRIO_PROCESS, 0);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "sigterm_bench: LCM could not start on " << url << "\n";
    return 1;
  }
  Listener listener;
  lcm.subscribe(std::string(kPrefix) + "_PLANNER_STATUS", &Listener::on_status, &listener);
  lcm.subscribe(std::string(kPrefix) + "_PLAN", &Listener::on_plan, &listener);

  std::vector<Trial> results;
  int retries = 0;
  for (int attempt = 0; static_cast<int>(results.size()) < trials; ++attempt) {
    if (attempt > 3 * trials) {
      std::cerr << "sigterm_bench: too many plans ended before the signal\n";
      return 1;
    }
    const int index = static_cast<int>(results.size());
    const std::string log = logs + "/sigterm_bench_" + std::to_string(index) + ".log";
    // The daemon at niceness 0 (as beside the busy loops) whatever this observer's niceness.
    std::vector<std::string> args = {"/usr/bin/nice", "-n", std::to_string(-own_nice),
                                     daemon,          scene, "--prefix",
                                     kPrefix,         "--lcm-url", url,
                                     "--status-period", "0.05"};
    args.insert(args.end(), daemon_args.begin(), daemon_args.end());
    listener.status.reset();
    listener.answer.reset();
    listener.goal_id = attempt + 1;
    const pid_t pid = spawn_daemon(args, log);
    const int pidfd = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
    if (pidfd < 0) {
      std::cerr << "sigterm_bench: pidfd_open failed\n";
      return 1;
    }
    Trial t;
    // A heartbeat of the new daemon (the last one's final heartbeat names its goal).
    bool ok = handle_until(lcm, 60, [&] {
      return listener.status.has_value() && listener.status->last_goal_id == -1;
    });
    kinograph::goal_t g{};
    g.goal_id = listener.goal_id;
    g.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
    g.kind = kinograph::goal_t::KIND_JOINT_CONFIGURATION;
    g.joint_position = goal_q;
    g.num_joints = static_cast<int32_t>(goal_q.size());
    g.ee_quaternion[0] = 1;
    if (ok) lcm.publish(std::string(kPrefix) + "_GOAL", &g);
    ok = ok && handle_until(lcm, 60, [&] {
           return listener.answer ||
                  (listener.status->state == kinograph::planner_status_t::PLANNING &&
                   listener.status->last_goal_id == g.goal_id);
         });
    if (!ok) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
      std::cerr << "sigterm_bench: the daemon did not start planning (log " << log << ")\n";
      return 1;
    }
    // Signals spread over the solve: trial i waits i/trials of the spread.
    t.delay_ms = spread_ms * index / trials;
    const auto planning_at = Clock::now();
    handle_until(lcm, t.delay_ms * 1e-3, [&] { return listener.answer.has_value(); });
    const bool ended_before = listener.answer.has_value();
    const auto signalled = Clock::now();
    kill(pid, SIGTERM);
    t.delay_ms = ms_between(planning_at, signalled);
    // Until the daemon exits, then what LCM still holds (its datagrams were sent before it).
    pollfd fds[2] = {{lcm.getFileno(), POLLIN, 0}, {pidfd, POLLIN, 0}};
    std::optional<Clock::time_point> exited;
    while (!exited) {
      if (poll(fds, 2, 60000) <= 0) break;
      const auto now = Clock::now();
      if (fds[1].revents & POLLIN) exited = now;
      listener.woken = now;
      if (fds[0].revents & POLLIN) lcm.handle();
      listener.woken.reset();
    }
    close(pidfd);
    int status = 0;
    if (!exited) kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    if (!exited) {
      std::cerr << "sigterm_bench: the daemon did not exit within 60 s (log " << log << ")\n";
      return 1;
    }
    handle_until(lcm, 1, [&] { return listener.answer.has_value(); });
    if (ended_before ||
        (listener.answer && listener.answer->status != kinograph::plan_t::CANCELLED)) {
      ++retries;  // the plan ended before the signal: nothing was cancelled
      continue;
    }
    t.exit_ms = ms_between(signalled, *exited);
    t.answer_ms = listener.answer ? ms_between(signalled, listener.answer_at) : std::nan("");
    t.status_message = listener.answer ? listener.answer->status_message : "no answer";
    t.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::ifstream in(log);
    const std::regex says("signal 15 received; every goal answered ([0-9.]+) ms after it");
    for (std::string line; std::getline(in, line);) {
      std::smatch m;
      if (std::regex_search(line, m, says)) t.daemon_says = m[1];
    }
    std::cerr << "trial " << index << ": signal " << t.delay_ms << " ms into the solve, answer "
              << t.answer_ms << " ms, exit " << t.exit_ms << " ms (code " << t.exit_code
              << "; daemon says " << t.daemon_says << " ms): " << t.status_message << "\n";
    results.push_back(t);
  }

  std::vector<double> answers, exits;
  int over_100 = 0, clean = 0;
  nlohmann::json runs = nlohmann::json::array();
  for (const Trial& t : results) {
    answers.push_back(t.answer_ms);
    exits.push_back(t.exit_ms);
    if (t.exit_ms > 100) ++over_100;
    if (t.exit_code == 0) ++clean;
    runs.push_back({{"delay_ms", t.delay_ms},
                    {"answer_ms", t.answer_ms},
                    {"exit_ms", t.exit_ms},
                    {"exit_code", t.exit_code},
                    {"daemon_ms", t.daemon_says},
                    {"status_message", t.status_message}});
  }
  using kinograph::bench::cell;
  using kinograph::bench::max_of;
  using kinograph::bench::median;
  const nlohmann::json out = {{"trials", trials},
                              {"retries", retries},
                              {"answer_ms_median", median(answers)},
                              {"answer_ms_max", max_of(answers)},
                              {"exit_ms_median", median(exits)},
                              {"exit_ms_max", max_of(exits)},
                              {"exits_over_100_ms", over_100},
                              {"clean_exits", clean},
                              {"runs", runs}};
  std::cout << out.dump(2) << "\n\n";
  std::cout << "| trials | CANCELLED answer median (ms) | max (ms) | exit median (ms) | max (ms) "
               "| exits > 100 ms | exit 0 |\n|---|---|---|---|---|---|---|\n";
  std::cout << "| " << trials << " | " << cell(median(answers), 1, 1) << " | "
            << cell(max_of(answers), 1, 1) << " | " << cell(median(exits), 1, 1) << " | "
            << cell(max_of(exits), 1, 1) << " | " << over_100 << " | " << clean << "/" << trials
            << " |\n";
  if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  return over_100 == 0 && clean == trials ? 0 : 3;
}
