#include "kinograph/planning/batch/path_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

#include "kinograph/collision/collision_world.h"
#include "kinograph/dynamics/data.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"

namespace kinograph::planning {
namespace {

constexpr double kStep = 1.0;         // rad (m): longest joint move of one tree extension
constexpr double kResolution = 0.07;  // rad (m): largest joint change between checked states
constexpr int kShortcutRounds = 40;   // random shortcut attempts on a found path

// Whether configurations keep their clearance: obstacles (their own threshold) and the floor
// and self pairs (theirs), each in a world of its own so the thresholds can differ.
class ClearanceTest {
 public:
  ClearanceTest(const Problem& problem, const PathSearchOptions& options)
      : model_(*problem.model), data_(model_), floor_and_self_(clearance_world(problem, false)) {
    if (!problem.obstacles.empty()) {
      obstacles_ = std::make_unique<collision::CollisionWorld>(model_);
      for (const collision::Obstacle& o : problem.obstacles) {
        const collision::Status s = obstacles_->add_obstacle(o);
        if (!s.ok)
          throw std::invalid_argument("obstacle " + std::to_string(o.id) + ": " + s.reason);
      }
    }
    obstacle_threshold_ = options.obstacle_clearance;
    self_threshold_ = problem.objectives.self_collision_epsilon;
  }

  // Lowers the thresholds to what the configuration q itself keeps (×0.9), so that a start or
  // goal closer than the options' clearance is still a valid end of the path.
  void admit(const Eigen::VectorXd& q) {
    dynamics::forward_kinematics(model_, data_, q);
    if (obstacles_) {
      obstacle_threshold_ =
          std::min(obstacle_threshold_, 0.9 * obstacles_->closest(data_, 0).distance);
    }
    self_threshold_ = std::min(self_threshold_, 0.9 * floor_and_self_->closest(data_, 0).distance);
  }

  // No pair within its threshold: any_within() culls the far pairs and stops at the first near
  // one, which is cheaper than finding the closest.
  bool clear(const Eigen::VectorXd& q) {
    dynamics::forward_kinematics(model_, data_, q);
    if (obstacles_ && obstacles_->any_within(data_, 0, obstacle_threshold_)) return false;
    return !floor_and_self_->any_within(data_, 0, self_threshold_);
  }

  // The segment a → b, sampled every `resolution` (b included, a assumed clear). The samples
  // are visited coarse to fine (odd multiples of halving strides), so a blocked segment is
  // usually refused after a few; the answer is the same as in order.
  bool clear(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double resolution) {
    const int n =
        std::max(1, static_cast<int>(std::ceil((b - a).cwiseAbs().maxCoeff() / resolution)));
    int top = 1;
    while (2 * top <= n) top *= 2;
    for (int stride = top; stride >= 1; stride /= 2) {
      for (int i = stride; i <= n; i += 2 * stride) {
        if (!clear(a + (b - a) * (static_cast<double>(i) / n))) return false;
      }
    }
    return true;
  }

  bool ends_clear() const { return obstacle_threshold_ >= 0 && self_threshold_ >= 0; }

 private:
  const dynamics::Model& model_;
  dynamics::Data data_;
  std::unique_ptr<collision::CollisionWorld> floor_and_self_, obstacles_;
  double obstacle_threshold_ = 0, self_threshold_ = 0;
};

// One tree of RRT-Connect: configurations and the index of each one's parent (−1 at the root).
struct Tree {
  std::vector<Eigen::VectorXd> nodes;
  std::vector<int> parent;

  int nearest(const Eigen::VectorXd& q) const {
    int best = 0;
    double d = std::numeric_limits<double>::infinity();
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
      const double di = (nodes[i] - q).squaredNorm();
      if (di < d) {
        d = di;
        best = i;
      }
    }
    return best;
  }
  int add(Eigen::VectorXd q, int from) {
    nodes.push_back(std::move(q));
    parent.push_back(from);
    return static_cast<int>(nodes.size()) - 1;
  }
  // Root → node i.
  std::vector<Eigen::VectorXd> branch(int i) const {
    std::vector<Eigen::VectorXd> out;
    for (; i >= 0; i = parent[i]) out.push_back(nodes[i]);
    std::reverse(out.begin(), out.end());
    return out;
  }
};

enum class Extend { kTrapped, kAdvanced, kReached };

// One step of at most `step` (largest joint move) from the nearest node toward q.
Extend extend(Tree& tree, const Eigen::VectorXd& q, ClearanceTest& test, int& added) {
  const int near = tree.nearest(q);
  const Eigen::VectorXd& from = tree.nodes[near];
  const Eigen::VectorXd d = q - from;
  const double longest = d.cwiseAbs().maxCoeff();
  const bool reaches = longest <= kStep;
  const Eigen::VectorXd to = reaches ? q : Eigen::VectorXd(from + d * (kStep / longest));
  if (!test.clear(from, to, kResolution)) return Extend::kTrapped;
  added = tree.add(to, near);
  return reaches ? Extend::kReached : Extend::kAdvanced;
}

}  // namespace

std::optional<std::vector<Eigen::VectorXd>> search_path(const Problem& problem,
                                                        const Eigen::VectorXd& q_goal,
                                                        const PathSearchOptions& options) {
  if (options.max_samples <= 0 || !problem.model || problem.model->collision.empty()) {
    return std::nullopt;
  }
  const dynamics::Model& model = *problem.model;
  const int n = model.nq();
  ClearanceTest test(problem, options);
  test.admit(problem.start_q);
  test.admit(q_goal);
  if (!test.ends_clear()) return std::nullopt;
  std::vector<Eigen::VectorXd> path;
  if (test.clear(problem.start_q, q_goal, kResolution)) {
    path = {problem.start_q, q_goal};
  } else {
    std::mt19937_64 rng(options.seed);
    Eigen::VectorXd lo(n), hi(n);
    const double margin = problem.objectives.limit_epsilon;
    for (int j = 0; j < n; ++j) {
      const dynamics::JointLimits& l = model.bodies[j].limits;
      lo[j] = std::isfinite(l.lower) ? l.lower + margin : -M_PI;
      hi[j] = std::isfinite(l.upper) ? l.upper - margin : M_PI;
      if (lo[j] > hi[j]) lo[j] = hi[j] = 0.5 * (l.lower + l.upper);
    }
    Tree a, b;
    a.add(problem.start_q, -1);
    b.add(q_goal, -1);
    bool a_is_start = true;
    Eigen::VectorXd q(n);
    for (int s = 0; s < options.max_samples && path.empty(); ++s) {
      for (int j = 0; j < n; ++j) q[j] = std::uniform_real_distribution<double>(lo[j], hi[j])(rng);
      int new_a = -1;
      if (extend(a, q, test, new_a) != Extend::kTrapped) {
        // Connect: the other tree steps toward the new node until it reaches it or is blocked.
        const Eigen::VectorXd target = a.nodes[new_a];
        int new_b = -1;
        Extend e = Extend::kAdvanced;
        while (e == Extend::kAdvanced) e = extend(b, target, test, new_b);
        if (e == Extend::kReached) {
          std::vector<Eigen::VectorXd> ha = a.branch(new_a), hb = b.branch(new_b);
          hb.pop_back();  // the meeting configuration is in both
          std::reverse(hb.begin(), hb.end());
          ha.insert(ha.end(), hb.begin(), hb.end());
          if (!a_is_start) std::reverse(ha.begin(), ha.end());
          path = std::move(ha);
        }
      }
      std::swap(a, b);
      a_is_start = !a_is_start;
    }
    if (path.empty()) return std::nullopt;
    // Shortcuts: a straight segment that stays clear replaces the configurations it skips.
    for (int r = 0; r < kShortcutRounds && path.size() > 2; ++r) {
      const int m = static_cast<int>(path.size());
      int i = std::uniform_int_distribution<int>(0, m - 1)(rng);
      int k = std::uniform_int_distribution<int>(0, m - 1)(rng);
      if (i > k) std::swap(i, k);
      if (k - i < 2) continue;
      if (test.clear(path[i], path[k], kResolution)) {
        path.erase(path.begin() + i + 1, path.begin() + k);
      }
    }
  }
  return path;
}

}  // namespace kinograph::planning
