#pragma once
// Tells the daemon's own heartbeats, looped back by LCM, from another daemon's on the same
// channel: two daemons on one prefix both answer every goal, with colliding plan ids.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>

namespace kinograph::daemon {

/// The heartbeats this daemon published lately, by utime (made strictly increasing), each with
/// a hash of its encoded bytes.
class OwnHeartbeats {
 public:
  enum class Verdict { kOurs, kForeign, kTooOld };
  /// Remembers at most `capacity` heartbeats; older ones can no longer be judged.
  explicit OwnHeartbeats(std::size_t capacity) : capacity_(capacity) {}
  /// The utime to stamp on the next heartbeat: `now`, or just after the last one.
  int64_t next_utime(int64_t now) const { return now > last_ ? now : last_ + 1; }
  /// Records a heartbeat about to be published.
  void record(int64_t utime, std::size_t hash);
  /// Whether a received heartbeat is one of ours, another publisher's (a utime we never used,
  /// or used for different bytes), or older than what is remembered (not judged).
  Verdict judge(int64_t utime, std::size_t hash) const;

 private:
  std::size_t capacity_;
  int64_t last_ = INT64_MIN;
  std::map<int64_t, std::size_t> hashes_;
  std::deque<int64_t> order_;
};

}  // namespace kinograph::daemon
