#include "daemon/log_limiter.h"

#include <cstdio>

namespace kinograph::daemon {

LogLimiter::LogLimiter(int lines_per_window, double window_s)
    : lines_per_window_(lines_per_window),
      window_(
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(window_s))) {}

std::string LogLimiter::summary(const std::string& kind, const Window& w,
                                Clock::time_point now) const {
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.1f",
                std::chrono::duration<double>(now - w.start).count());
  return "… " + std::to_string(w.left_out) + " more rejected messages on " + kind +
         " in the last " + seconds + " s";
}

bool LogLimiter::admit(const std::string& kind, Clock::time_point now,
                       std::vector<std::string>& summaries) {
  auto [it, fresh] = windows_.try_emplace(kind, Window{now});
  Window& w = it->second;
  if (!fresh && now - w.start >= window_) {
    if (w.left_out > 0) summaries.push_back(summary(kind, w, now));
    w = Window{now};
  }
  if (w.logged < lines_per_window_) {
    ++w.logged;
    return true;
  }
  ++w.left_out;
  return false;
}

std::vector<std::string> LogLimiter::flush(Clock::time_point now) {
  std::vector<std::string> summaries;
  for (auto& [kind, w] : windows_) {
    if (w.left_out > 0 && now - w.start >= window_) {
      summaries.push_back(summary(kind, w, now));
      w = Window{now};
    }
  }
  return summaries;
}

}  // namespace kinograph::daemon
