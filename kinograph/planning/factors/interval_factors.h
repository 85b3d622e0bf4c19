#pragma once
// The dynamics between two knots on the plan's interpolant (interpolant.h): the shooting defect
// of the unactuated joints, which follow the robot's dynamics from knot k and must arrive at
// knot k+1, and the effort, q and q̇ limits at interior points of the interval.
#include <memory>
#include <string>
#include <vector>

#include "kinograph/dynamics/model.h"
#include "kinograph/planning/factors/constrained_factor.h"
#include "kinograph/planning/factors/interval_workspace.h"
#include "kinograph/planning/interpolant.h"

namespace kinograph::planning {

/// Which limit rows an interval's interior points hold (bits; IntervalDynamicsOptions and the
/// batch planner's constraint generation).
enum IntervalLimitRows : char {
  kNoLimitRows = 0,
  kMotionLimitRows = 1,  ///< q and q̇: the interpolant alone
  kEffortLimitRows = 2,  ///< τ of the actuated joints: inverse dynamics at every point
  kAllLimitRows = kMotionLimitRows | kEffortLimitRows,
};

/// Options of IntervalDynamicsFactor.
struct IntervalDynamicsOptions {
  int checks = 0;              ///< interior points i/(checks+1)·Δt where limits are enforced
  /// Which limits the interior points enforce (IntervalLimitRows bits). Without the effort
  /// rows a fully actuated robot's points need no dynamics: the cubic alone.
  int limit_rows = kAllLimitRows;
  double limit_epsilon = 0;    ///< limits tightened by this (as at the knots)
  double defect_scale = 1;     ///< × Δt² (position rows) and × Δt (velocity rows), as collocation
  double torque_scale = 1;     ///< scale (N·m) of the effort rows
  double limit_scale = 0.1;    ///< scale (rad, rad/s) of the q and q̇ rows
  /// Longest RK4 step (s) of the unactuated joints: the interpolant's, or longer for a coarse
  /// warm-up of the batch planner (same rows, cheaper, only approximately the interpolant).
  double integration_step = kMaxIntegrationStep;
};

/// Interval k of an n-joint robot, keys q_k v_k a_k q_{k+1} v_{k+1} a_{k+1}. Rows: for each
/// unactuated joint u an equality q_{k+1,u} − q_u(Δt) = 0, then one q̇_{k+1,u} − q̇_u(Δt) = 0
/// (the shooting defect); then at each interior check point, bounds on τ of every actuated
/// joint with a finite effort limit, on q with finite position limits and on q̇ with a finite
/// velocity limit (those of options.limit_rows). Jacobians exact through the RK4 sensitivities
/// (dynamics::rnea_derivatives); while linearizing, a check point's derivatives are computed
/// only when one of its rows is on (an inactive bound contributes nothing to the step), the
/// rest from inverse dynamics alone.
class IntervalDynamicsFactor final : public ConstrainedFactor {
 public:
  /// Evaluates in `workspace` (shared with the graph's other interval factors; its own when
  /// null). Throws std::invalid_argument if the interval would have no rows, dt ≤ 0, or the
  /// workspace is for another model or RK4 step than `options.integration_step`.
  IntervalDynamicsFactor(int k, double dt, std::shared_ptr<const dynamics::Model> model,
                         const IntervalDynamicsOptions& options,
                         std::shared_ptr<IntervalWorkspace> workspace = nullptr);
  void compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
               const graph::Jacobians* J) const override;
  bool parallel_safe() const override { return true; }  // its workspace is per worker
  /// A defect row as the unactuated joint missing the next knot (joint, times, amount); a limit
  /// row as the joint's q, q̇ or τ against its limit at the interior point's own time.
  std::string describe_row(int row, double z, const RowContext& c) const override;

  /// What each row of an interval measures (also used to tell whether the factor is needed).
  struct Row {
    enum class Kind { kDefectQ, kDefectQd, kTau, kQ, kQd };
    Kind kind = Kind::kDefectQ;
    int joint = 0;
    int point = -1;  ///< index of the interior check point (−1 for defect rows)
  };
  static std::vector<Row> layout(const dynamics::Model& model, const IntervalDynamicsOptions& o);

 private:
  // Fills row `row`'s Jacobian from the point's derivatives (n × 4n over q_k, q̇_k, q̈_k,
  // q̈_{k+1}), with the sign of the value: added to a zeroed row, or written `whole` (every
  // block) into an unzeroed one.
  void jacobian_row(int row, const Eigen::MatrixXd& d, double sign, const graph::Jacobians& J,
                    bool whole = false) const;

  std::shared_ptr<const dynamics::Model> model_;
  double dt_;
  std::vector<Row> layout_;
  std::vector<double> times_;      // interior check points, then Δt
  std::vector<int> point_begin_;   // first row of each check point (and the row count last)
  int defect_rows_ = 0;
  bool effort_rows_ = false;  // τ at the check points: inverse dynamics at every evaluation
  std::shared_ptr<IntervalWorkspace> workspace_;
};

}  // namespace kinograph::planning
