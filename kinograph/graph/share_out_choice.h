#pragma once
// Whether to share a repeated job out among threads (share_out) or run it on the caller's
// alone, from the times both ways have taken: on a machine whose other cores are busy, a
// shared job waits for threads the machine does not run, and the caller alone is faster.
#include <cstddef>

namespace kinograph::graph {

/// Times jobs both ways, per unit of work, and keeps to the faster, trying the other way every
/// kProbeEvery jobs since the machine's load changes. The first job is shared and not timed
/// (first evaluations carry one-time costs); the next is shared and the one after runs alone,
/// each timed.
class ShareOutChoice {
 public:
  /// Jobs between two tries of the way that was slower.
  static constexpr int kProbeEvery = 16;

  /// Whether the next job should be shared out.
  bool share() {
    if (jobs_ < 2) return true;
    if (per_unit_[0] == 0) return false;
    const bool faster = per_unit_[1] < per_unit_[0];
    if (++since_probe_ >= kProbeEvery) {
      since_probe_ = 0;
      return !faster;
    }
    return faster;
  }
  /// Records a job's wall time, `shared` or not, over `units` of work (e.g. factors).
  void record(bool shared, size_t units, double seconds) {
    if (jobs_++ == 0 || units == 0) return;
    per_unit_[shared ? 1 : 0] = seconds / static_cast<double>(units);
  }

 private:
  int jobs_ = 0;
  int since_probe_ = 0;
  double per_unit_[2] = {0, 0};  // seconds per unit alone, shared; 0 until timed
};

}  // namespace kinograph::graph
