#include "kinograph/planning/factors/collision_factors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "kinograph/collision/segment_checker.h"
#include "kinograph/dynamics/kinematics.h"
#include "kinograph/planning/clearance_world.h"
#include "kinograph/planning/factors/trajectory_factors.h"
#include "kinograph/planning/user_terms.h"

namespace kinograph::planning {

namespace {
collision::CollisionWorldOptions world_options_of(double query_distance, const SelfPairs* self,
                                                  bool cull) {
  collision::CollisionWorldOptions o;
  o.query_distance = query_distance;
  o.cull = cull;
  if (self != nullptr) {
    o.self_collision = true;
    o.self_collision_excluded = self->allowed;
  }
  return o;
}
}  // namespace

CollisionScratch::CollisionScratch(const dynamics::Model& model,
                                   const collision::CollisionWorldOptions& options)
    : world(model, options),
      data(model),
      gradient_workspace(model),
      gradient(model.nq()),
      q(model.nq()) {}

CollisionContext::CollisionContext(std::shared_ptr<const dynamics::Model> m,
                                   const std::vector<collision::Obstacle>& obs, double query_dist,
                                   const SelfPairs* self, bool cull)
    : model(std::move(m)),
      world_options(world_options_of(query_dist, self, cull)),
      obstacles(obs),
      scratch([this] {
        auto s = std::make_unique<CollisionScratch>(*model, world_options);
        for (const collision::Obstacle& o : obstacles) {
          const collision::Status status = s->world.add_obstacle(o);
          if (!status.ok) {
            throw std::invalid_argument("obstacle " + std::to_string(o.id) + ": " + status.reason);
          }
        }
        return s;
      }),
      query_distance(query_dist),
      lever(collision::SegmentChecker(*model).lever()) {
  for (const collision::Obstacle& o : obstacles) {
    obstacle_ids.push_back(o.id);
    moving = moving || o.is_moving();
  }
  row_of.assign(model->collision.size(), std::vector<int>(obstacle_ids.size(), -1));
  for (size_t g = 0; g < model->collision.size(); ++g) {
    if (model->collision[g].body < 0) continue;
    geoms.push_back(static_cast<int>(g));
    for (size_t o = 0; o < obstacle_ids.size(); ++o) row_of[g][o] = num_pairs++;
  }
  num_obstacle_rows = num_pairs;
  self_row_of.assign(model->collision.size(), std::vector<int>(model->collision.size(), -1));
  if (self != nullptr) {
    self_epsilon = self->epsilon;
    for (const auto& [a, b] : scratch.local().world.self_pairs())
      self_row_of[a][b] = self_row_of[b][a] = num_pairs++;
  }
}

collision::Status CollisionContext::move_obstacle(int id, const Eigen::Isometry3d& pose) {
  collision::Status status = collision::Status::success();  // the caller's world always exists
  scratch.for_each([&](CollisionScratch& s) {
    collision::Status moved = s.world.move_obstacle(id, pose);
    if (!moved.ok) status = std::move(moved);
  });
  if (!status.ok) return status;
  ++version;
  moving = false;
  for (collision::Obstacle& o : obstacles) {
    if (o.id == id) {
      o.pose = pose;
      o.trajectory = {};
    }
    moving = moving || o.is_moving();
  }
  return status;
}

int CollisionContext::row(const collision::Proximity& p) const {
  if (p.robot_geom < 0) return -1;
  if (p.is_self_collision()) return self_row_of[p.robot_geom][p.other_geom];
  for (size_t o = 0; o < obstacle_ids.size(); ++o) {
    if (obstacle_ids[o] == p.obstacle) return row_of[p.robot_geom][o];
  }
  return -1;
}

namespace {
std::vector<graph::Key> collision_keys(int k, double s) {
  if (s == 0) return {q_key(k)};
  return {q_key(k), v_key(k), q_key(k + 1), v_key(k + 1)};
}
std::vector<RowSpec> collision_rows(const CollisionContext& c, double epsilon, double scale) {
  if (c.num_pairs == 0) {
    throw std::invalid_argument("CollisionFactor needs robot geometry and obstacles or self pairs");
  }
  RowSpec r;
  r.kind = RowKind::kBounds;
  r.lower = epsilon;
  r.upper = std::numeric_limits<double>::infinity();
  r.scale = scale;
  std::vector<RowSpec> rows(c.num_pairs, r);
  for (int i = c.num_obstacle_rows; i < c.num_pairs; ++i) rows[i].lower = c.self_epsilon;
  return rows;
}
}  // namespace

CollisionFactor::CollisionFactor(int k, double s, double dt, double epsilon, double scale,
                                 std::shared_ptr<CollisionContext> context)
    : ConstrainedFactor(collision_keys(k, s),
                        std::vector<int>(s == 0 ? 1 : 4, context->model->nq()),
                        collision_rows(*context, epsilon, scale)),
      s_(s),
      dt_(dt),
      t_((k + s) * dt),
      ctx_(std::move(context)) {
  if (!(s >= 0 && s < 1)) throw std::invalid_argument("CollisionFactor needs 0 <= s < 1");
  double widest = -std::numeric_limits<double>::infinity();
  for (const RowSpec& r : rows()) widest = std::max(widest, r.lower);
  hinge_query_distance_ = std::min(ctx_->query_distance, widest);
  const double s2 = s * s, s3 = s2 * s;
  h_ << 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2;
  cache_values();
  list_written_rows();  // only near pairs have a gradient: most rows stay zero
}

void CollisionFactor::compute(const graph::FactorValues& x, Eigen::Ref<Eigen::VectorXd> z,
                              const graph::Jacobians* J) const {
  const CollisionContext& ctx = *ctx_;
  CollisionScratch& c = ctx_->scratch.local();
  const dynamics::Model& model = *ctx.model;
  Eigen::VectorXd& q = c.q;
  if (s_ == 0) {
    q = x[0];
  } else {
    q = h_[0] * x[0] + h_[1] * dt_ * x[1] + h_[2] * x[2] + h_[3] * dt_ * x[3];
  }
  // Every distance moves by at most 2 Σ_j lever_j |Δq_j| (both geometries of a self pair move)
  // from the last query's: while that stays below the last smallest gap and no multiplier is
  // positive, every row stays beyond its ε with its hinge off, so the last distances stand in
  // for the query (the factor's rows and Jacobian are zero either way).
  const bool no_multipliers = bound_multipliers_zero();
  if (last_.version == ctx.version && !ctx.moving && last_.gap > 0 && no_multipliers &&
      2 * ctx.lever.dot((q - last_.q).cwiseAbs()) < last_.gap) {
    z = last_.z;
    rows_proven_clear();
    return;
  }
  dynamics::forward_kinematics(model, c.data, q);
  z.setConstant(ctx.query_distance);
  // Values alone without multipliers (a cost or a violation) need only the pairs within their
  // ε: every other hinge is off at any distance beyond it. Most pairs the query reports lie
  // between ε and the query distance, and GJK is most of a query's time.
  const bool hinges_only = J == nullptr && no_multipliers;
  for (const collision::Proximity& p :
       hinges_only ? c.world.query(c.data, t_, hinge_query_distance_)
                   : c.world.query(c.data, t_)) {
    const int row = ctx.row(p);
    if (row < 0) continue;
    z[row] = p.distance;
    if (J == nullptr) continue;
    collision::distance_gradient(model, c.data, p, c.gradient_workspace, c.gradient);
    if (graph::RowSupport* written = J->row_support()) written->rows.push_back(row);
    if (s_ == 0) {
      J->block(0).row(row) = c.gradient.transpose();
    } else {
      J->block(0).row(row) = h_[0] * c.gradient.transpose();
      J->block(1).row(row) = h_[1] * dt_ * c.gradient.transpose();
      J->block(2).row(row) = h_[2] * c.gradient.transpose();
      J->block(3).row(row) = h_[3] * dt_ * c.gradient.transpose();
    }
  }
  double gap = std::numeric_limits<double>::infinity();
  for (int i = 0; i < residual_dim(); ++i) {
    const double row_gap = z[i] - rows()[static_cast<size_t>(i)].lower;
    if (std::isnan(row_gap)) {  // a distance without a value: never taken as clear
      gap = row_gap;
      break;
    }
    gap = std::min(gap, row_gap);
  }
  if (gap > 0 && no_multipliers) rows_proven_clear();  // every row beyond its ε
  if (hinges_only) {
    clear_rows_not_measured();
    return;  // the last query stays the one that measured every pair it stands in for
  }
  last_.q = q;
  last_.z = z;
  last_.gap = gap;
  last_.version = ctx.version;
}

namespace {
// The pair of row `row` in the user's terms ("link 'a' and obstacle 3", "link 'a' and the
// floor", "links 'a' and 'b'"), empty when the row is not in the context.
std::string collision_pair(const CollisionContext& ctx, int row) {
  const auto link = [&](size_t g) { return "'" + ctx.model->collision[g].link_name + "'"; };
  for (size_t g = 0; g < ctx.row_of.size(); ++g) {
    for (size_t slot = 0; slot < ctx.row_of[g].size(); ++slot) {
      if (ctx.row_of[g][slot] != row) continue;
      const int id = ctx.obstacle_ids[slot];
      return "link " + link(g) +
             (id == kFloorId ? std::string(" and the floor")
                             : " and obstacle " + std::to_string(id));
    }
  }
  for (size_t a = 0; a < ctx.self_row_of.size(); ++a) {
    for (size_t b = a + 1; b < ctx.self_row_of[a].size(); ++b) {
      if (ctx.self_row_of[a][b] == row) return "links " + link(a) + " and " + link(b);
    }
  }
  return "";
}
}  // namespace

std::string CollisionFactor::describe_row(int row, double z, const RowContext&) const {
  const std::string pair = collision_pair(*ctx_, row);
  if (pair.empty()) return "";
  if (z < 0) return pair + " overlap by " + number(-z) + " m at " + at_time(t_);
  return pair + " are " + number(z) + " m apart at " + at_time(t_) + ", inside the planner's " +
         number(rows()[static_cast<size_t>(row)].lower) + " m safety distance";
}

}  // namespace kinograph::planning
