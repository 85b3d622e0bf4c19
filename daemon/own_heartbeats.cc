#include "daemon/own_heartbeats.h"

namespace kinograph::daemon {

void OwnHeartbeats::record(int64_t utime, std::size_t hash) {
  last_ = utime;
  hashes_[utime] = hash;
  order_.push_back(utime);
  while (order_.size() > capacity_) {
    hashes_.erase(order_.front());
    order_.pop_front();
  }
}

OwnHeartbeats::Verdict OwnHeartbeats::judge(int64_t utime, std::size_t hash) const {
  // Before the oldest remembered one (or before any was published) nothing can be told.
  if (order_.empty() || utime < order_.front()) return Verdict::kTooOld;
  auto it = hashes_.find(utime);
  return it != hashes_.end() && it->second == hash ? Verdict::kOurs : Verdict::kForeign;
}

}  // namespace kinograph::daemon
