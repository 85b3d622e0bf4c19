#pragma once
// Anyone on the network can send junk as fast as it likes: the daemon logs at most a few
// rejections per second of each kind, and then one line saying how many it left out.
#include <chrono>
#include <map>
#include <string>
#include <vector>

namespace kinograph::daemon {

/// Rate limit on log lines, per kind (e.g. the channel a rejected message came on).
class LogLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  /// At most `lines_per_window` lines of each kind per window of `window_s` seconds.
  LogLimiter(int lines_per_window, double window_s);
  /// Whether a line of `kind` may be logged at `now`; when the kind's previous window had lines
  /// left out, their summary is appended to `summaries` first.
  bool admit(const std::string& kind, Clock::time_point now, std::vector<std::string>& summaries);
  /// Summaries of the windows that have ended with lines left out (called periodically, so a
  /// burst that stops is still summarised).
  std::vector<std::string> flush(Clock::time_point now);

 private:
  struct Window {
    Clock::time_point start;
    int logged = 0;
    long left_out = 0;
  };
  std::string summary(const std::string& kind, const Window& w, Clock::time_point now) const;
  int lines_per_window_;
  Clock::duration window_;
  std::map<std::string, Window> windows_;
};

}  // namespace kinograph::daemon
