// A daemon's neighbours over an in-process memq:// LCM: a neighbour's valid plan is followed,
// whatever its priority, and one without a plan held at its state; its bodies are named in reasons, a heartbeat
// whose model or base does not fit its scene is reported, failure answers change nothing, and
// a goal refused by a neighbour is tried again once per new plan of it, following it, up to the
// bound.
#include "daemon/neighbours.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <limits>
#include <lcm/lcm-cpp.hpp>

#include "kinograph/fleet/joint_clearance.h"
#include "kinograph/fleet/model_id.h"
#include "kinograph/fleet/neighbour_bodies.h"
#include "kinograph/lcm/message_convert.h"
#include "kinograph/plan_t.hpp"
#include "kinograph/planner_status_t.hpp"
#include "kinograph/robot_state_t.hpp"
#include "kinograph/planning/io/scene.h"

namespace kinograph::daemon {
namespace {

class NeighboursTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(lcm_.good());
    spec_ = neighbour_from_option("right=" + std::string(KINOGRAPH_SOURCE_DIR) +
                                  "/robots/scenes/iiwa_pair_right.yaml");
    neighbours_ = std::make_unique<Neighbours>(std::vector<NeighbourSpec>{spec_}, "LEFT",
                                               NeighboursOptions{});
    neighbours_->subscribe(lcm_, [] {});
  }
  void TearDown() override { neighbours_->unsubscribe(lcm_); }
  // Publishes and handles everything queued.
  template <class Message>
  void send(const std::string& channel, const Message& m) {
    lcm_.publish(channel, &m);
    while (lcm_.handleTimeout(0) > 0) {
    }
  }
  planner_status_t heartbeat(int64_t goal_utime) const {
    planner_status_t m;
    m.robot = "iiwa14";
    m.model_id = fleet::model_id(*spec_.model);
    const Eigen::Quaterniond turn(spec_.base.linear());
    for (int i = 0; i < 3; ++i) m.base_position[i] = spec_.base.translation()[i];
    m.base_quaternion[0] = turn.w();
    m.base_quaternion[1] = turn.x();
    m.base_quaternion[2] = turn.y();
    m.base_quaternion[3] = turn.z();
    m.goal_utime = goal_utime;
    m.valid_plan_id = 7;
    m.planning_goal_utime = -1;
    return m;
  }
  plan_t plan(int64_t id, int8_t status = plan_t::SUCCESS) const {
    return moving_plan(id, spec_.start_q, spec_.start_q, status);
  }
  // Right's plan of 1 s from `from` to `to` (at `from` for its first 0.3 s, at `to` for its last),
  // starting 5 s into the common clock.
  plan_t moving_plan(int64_t id, const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                     int8_t status = plan_t::SUCCESS) const {
    planning::Plan p;
    const int n = spec_.model->nq(), knots = 10;
    p.q = p.qd = p.qdd = p.tau = Eigen::MatrixXd::Zero(knots + 1, n);
    for (int k = 0; k <= knots; ++k) {
      p.t.push_back(0.1 * k);
      const double s = std::clamp((k - 3) / 4.0, 0.0, 1.0);
      p.q.row(k) = ((1 - s) * from + s * to).transpose();
    }
    p.validation.valid = true;
    messages::PlanTime time;
    time.start_utime = 5'000'000;
    plan_t m = messages::plan_to_message(p, *spec_.model, "iiwa14", id, 1, time);
    m.status = status;
    return m;
  }

  lcm::LCM lcm_{"memq://"};
  NeighbourSpec spec_;
  std::unique_ptr<Neighbours> neighbours_;
};

TEST_F(NeighboursTest, FollowsAHigherNeighboursPlanAndNamesItsBodies) {
  send("RIGHT_PLANNER_STATUS", heartbeat(1'000'000));
  send("RIGHT_PLAN", plan(7));
  EXPECT_TRUE(neighbours_->take_changed());
  EXPECT_FALSE(neighbours_->take_changed());
  // Own goal at 2 s: right (goal at 1 s) has priority and is followed along its plan.
  const fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  ASSERT_EQ(d.treatment.size(), 1u);
  EXPECT_EQ(d.treatment[0], fleet::Treatment::kAlongPlan);
  std::vector<collision::Obstacle> obstacles;
  neighbours_->add_obstacles(d, 4'000'000, obstacles);
  ASSERT_EQ(obstacles.size(), spec_.model->collision.size());
  int moving = 0;
  for (const auto& o : obstacles) {
    EXPECT_GE(o.id, Neighbours::kFirstObstacleId);
    moving += o.is_moving();
  }
  EXPECT_GT(moving, 0);
  const int id = obstacles.back().id;
  EXPECT_EQ(neighbours_->name_bodies("link 'a' and obstacle " + std::to_string(id) + " overlap"),
            "link 'a' and neighbour 'right' link '" + spec_.model->collision.back().link_name +
                "' overlap");
  neighbours_->planned(d, true, nullptr);
  EXPECT_NE(neighbours_->summary().find("right: plan 7, followed"), std::string::npos)
      << neighbours_->summary();
  EXPECT_FALSE(neighbours_->decide({2'000'000, ""}, false).replan);

  // A failure answer leaves it on its plan; the same plan sent again is no change.
  send("RIGHT_PLAN", plan(8, plan_t::NOT_CONVERGED));
  send("RIGHT_PLAN_CURRENT", plan(7));
  EXPECT_FALSE(neighbours_->take_changed());
  EXPECT_FALSE(neighbours_->decide({2'000'000, ""}, false).replan);
  // A new plan of it: one replan.
  send("RIGHT_PLAN", plan(9));
  EXPECT_TRUE(neighbours_->decide({2'000'000, ""}, false).replan);
}

// Whom to yield to: a neighbour heard lately making a plan for a goal that outranks the own one
// (ties by prefix, "LEFT" before "RIGHT"); its plan in the making is no change to replan for.
TEST_F(NeighboursTest, YieldsOnlyToANeighbourMakingAPlanOfHigherPriority) {
  EXPECT_EQ(neighbours_->planning_above(2'000'000), "");  // not heard yet
  planner_status_t hb = heartbeat(1'000'000);
  send("RIGHT_PLANNER_STATUS", hb);
  EXPECT_TRUE(neighbours_->take_changed());
  EXPECT_EQ(neighbours_->planning_above(2'000'000), "");  // heard, not planning
  hb.planning_goal_utime = 1'500'000;
  send("RIGHT_PLANNER_STATUS", hb);
  EXPECT_FALSE(neighbours_->take_changed());
  EXPECT_EQ(neighbours_->planning_above(2'000'000), "right");
  EXPECT_EQ(neighbours_->planning_above(1'000'000), "");  // the own goal is earlier
  hb.planning_goal_utime = 2'000'000;
  send("RIGHT_PLANNER_STATUS", hb);
  EXPECT_EQ(neighbours_->planning_above(2'000'000), "");  // a tie: LEFT outranks RIGHT
  EXPECT_EQ(neighbours_->planning_above(2'000'001), "right");
}

// A neighbour gone silent while planning is not waited for.
TEST(NeighboursYield, DoesNotYieldToASilentNeighbour) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  NeighbourSpec spec = neighbour_from_option("right=" + std::string(KINOGRAPH_SOURCE_DIR) +
                                             "/robots/scenes/iiwa_pair_right.yaml");
  // Long enough that the first look always comes within it, even on a busy machine.
  Neighbours neighbours({spec}, "LEFT", NeighboursOptions{.timeout_s = 2.0});
  neighbours.subscribe(lcm, [] {});
  planner_status_t hb{};
  hb.model_id = fleet::model_id(*spec.model);
  hb.base_quaternion[0] = 1;
  hb.goal_utime = -1;
  hb.planning_goal_utime = 1'000'000;
  lcm.publish("RIGHT_PLANNER_STATUS", &hb);
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(neighbours.planning_above(2'000'000), "right");
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // beyond the timeout, at least
  EXPECT_EQ(neighbours.planning_above(2'000'000), "");
  neighbours.unsubscribe(lcm);
}

TEST_F(NeighboursTest, HoldsALowerNeighbourWithoutAPlanAndFollowsItsPlanWithoutReplanningForIt) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));
  fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  EXPECT_EQ(d.treatment[0], fleet::Treatment::kHeldAtState);
  std::vector<collision::Obstacle> obstacles;
  neighbours_->add_obstacles(d, 4'000'000, obstacles);
  ASSERT_EQ(obstacles.size(), spec_.model->collision.size());
  for (const auto& o : obstacles) EXPECT_FALSE(o.is_moving());
  // Its plan in force is planned around, as every neighbour's is.
  send("RIGHT_PLAN", plan(7));
  d = neighbours_->decide({2'000'000, ""}, true);
  EXPECT_EQ(d.treatment[0], fleet::Treatment::kAlongPlan);
  neighbours_->planned(d, true, nullptr);
  obstacles.clear();
  neighbours_->add_obstacles(d, 4'000'000, obstacles);
  EXPECT_TRUE(std::any_of(obstacles.begin(), obstacles.end(),
                          [](const collision::Obstacle& o) { return o.is_moving(); }));
  send("RIGHT_PLAN", plan(8));  // it yields: no replan here
  EXPECT_FALSE(neighbours_->decide({2'000'000, ""}, false).replan);
}

// A measured state newer than the end of a neighbour's plan says where it is now (a robot moved
// by hand, a restarted one): it is held there, not at the plan's last knot.
TEST_F(NeighboursTest, AStateNewerThanTheEndOfItsPlanWins) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));
  send("RIGHT_PLAN", plan(7));  // 5–6 s on the common clock
  const fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  ASSERT_EQ(d.treatment[0], fleet::Treatment::kAlongPlan);
  Eigen::VectorXd elsewhere = spec_.start_q;
  elsewhere[0] += 0.5;
  robot_state_t state{};
  state.robot = spec_.model->name;
  state.num_joints = spec_.model->nq();
  for (int j = 0; j < spec_.model->nq(); ++j) state.joint_name.push_back(spec_.model->bodies[j].joint_name);
  state.position.assign(elsewhere.data(), elsewhere.data() + elsewhere.size());
  state.velocity.assign(elsewhere.size(), 0.0);
  const auto moving_bodies = [&] {
    std::vector<collision::Obstacle> obstacles;
    neighbours_->add_obstacles(d, 7'000'000, obstacles);
    return std::count_if(obstacles.begin(), obstacles.end(),
                         [](const collision::Obstacle& o) { return o.is_moving(); });
  };
  state.utime = 5'500'000;  // during the plan: the plan is followed
  send("RIGHT_STATE", state);
  EXPECT_GT(moving_bodies(), 0);
  state.utime = 6'500'000;  // after it ended
  send("RIGHT_STATE", state);
  EXPECT_EQ(moving_bodies(), 0);
  const std::vector<fleet::NeighbourBody> at_state =
      fleet::bodies_at({"right", spec_.model}, elsewhere, Neighbours::kFirstObstacleId);
  std::vector<collision::Obstacle> obstacles;
  neighbours_->add_obstacles(d, 7'000'000, obstacles);
  ASSERT_EQ(obstacles.size(), at_state.size());
  for (std::size_t g = 0; g < obstacles.size(); ++g) {
    EXPECT_TRUE(obstacles[g].pose.isApprox(at_state[g].obstacle.pose, 1e-12)) << "body " << g;
  }
}

TEST_F(NeighboursTest, ReportsAHeartbeatThatDoesNotFitTheScene) {
  planner_status_t wrong_model = heartbeat(1);
  wrong_model.model_id = "iiwa14:0000000000000000";
  send("RIGHT_PLANNER_STATUS", wrong_model);
  EXPECT_NE(neighbours_->summary().find("its model is iiwa14:0000000000000000"), std::string::npos)
      << neighbours_->summary();
  planner_status_t moved = heartbeat(1);
  moved.base_position[1] = 0.5;
  send("RIGHT_PLANNER_STATUS", moved);
  EXPECT_NE(neighbours_->summary().find("its base is 0.5 m"), std::string::npos)
      << neighbours_->summary();
}

TEST_F(NeighboursTest, FindsTheNeighbourAPlanRunsIntoAndWhetherItIsBlockedByThisRobot) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));
  const fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  ASSERT_EQ(d.treatment[0], fleet::Treatment::kHeldAtState);
  // Standing where right stands (its scene's start, no state heard): right blocks it.
  std::string why;
  const std::optional<fleet::Blocker> b = neighbours_->blocker(
      d, 4'000'000, *spec_.model, fleet::standing_plan(spec_.start_q), 0.0, 0.0, 0.0, why);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->name, "right");
  EXPECT_EQ(b->prefix, "RIGHT");
  EXPECT_EQ(b->treatment, fleet::Treatment::kHeldAtState);
  EXPECT_FALSE(b->blocked_by_own);
  EXPECT_NE(why.find("overlap"), std::string::npos) << why;
  // Left's own start, across the table, is clear of it.
  const planning::Scene left = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                    "/robots/scenes/iiwa_pair_left.yaml");
  EXPECT_FALSE(neighbours_
                   ->blocker(d, 4'000'000, *left.problem.model,
                             fleet::standing_plan(left.problem.start_q), 0.0, 0.0, 0.0, why)
                   .has_value())
      << why;

  // Right's heartbeat says LEFT blocks its goal: a change, and the blocker is now blocked by it.
  neighbours_->take_changed();
  planner_status_t blocked = heartbeat(3'000'000);
  blocked.message = fleet::blocked_reason("left", "LEFT", fleet::Treatment::kHeldAtState, 0, "x");
  send("RIGHT_PLANNER_STATUS", blocked);
  EXPECT_TRUE(neighbours_->take_changed());
  EXPECT_EQ(neighbours_->blocking_cycle("right"), std::vector<std::string>{"RIGHT"});
  EXPECT_TRUE(
      neighbours_
          ->blocker(d, 4'000'000, *spec_.model, fleet::standing_plan(spec_.start_q), 0.0, 0.0, 0.0, why)
          ->blocked_by_own);
  // Blocked by another robot: not by this one.
  blocked.message = fleet::blocked_reason("x", "OTHER", fleet::Treatment::kHeldAtState, 0, "x");
  send("RIGHT_PLANNER_STATUS", blocked);
  EXPECT_TRUE(neighbours_->blocking_cycle("right").empty());
}

// A configuration of right that reaches into left standing at its scene's start (right's own
// start is clear of it): found on a grid of its turn, shoulder and elbow.
Eigen::VectorXd reaching_into(const NeighbourSpec& right, const planning::Scene& left) {
  const std::shared_ptr<const dynamics::Model> left_model(left.problem.model);
  const fleet::RobotPlan at_left{"left", left_model, fleet::standing_plan(left.problem.start_q)};
  for (double turn = -0.8; turn < 0.9; turn += 0.4) {
    for (double shoulder = 0.5; shoulder < 1.6; shoulder += 0.1) {
      for (double elbow = -1.0; elbow < 0.1; elbow += 0.2) {
        Eigen::VectorXd q = Eigen::VectorXd::Zero(right.model->nq());
        q[0] = turn;
        q[1] = shoulder;
        q[3] = elbow;
        const fleet::RobotPlan at_q{"right", right.model, fleet::standing_plan(q)};
        if (fleet::joint_clearance({at_left, at_q}).min_distance < -0.02) return q;
      }
    }
  }
  return {};
}

// Left's scene and a configuration of right reaching into left standing at its start.
class ReachingIntoLeftTest : public NeighboursTest {
 protected:
  void SetUp() override {
    NeighboursTest::SetUp();
    into = reaching_into(spec_, left);
    ASSERT_EQ(into.size(), spec_.model->nq()) << "no configuration of right reaches into left";
  }
  const planning::Scene left = planning::load_scene(std::string(KINOGRAPH_SOURCE_DIR) +
                                                    "/robots/scenes/iiwa_pair_left.yaml");
  Eigen::VectorXd into;
};

// The blind spot of a daemon's first plan without states (the bench's): it starts at the scene's
// start, where the robot has stood until then. A higher neighbour's plan that swept through it
// before then is not followed, though from knot 0 on the two keep clear.
TEST_F(ReachingIntoLeftTest, ChecksAPlanFromNoStateAgainstWhatAFollowedPlanDidBeforeIt) {
  send("RIGHT_PLANNER_STATUS", heartbeat(1'000'000));  // earlier than left's goal: higher
  send("RIGHT_PLAN", moving_plan(3, into, spec_.start_q));  // 5–6 s: through left, then home
  const fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  ASSERT_EQ(d.treatment[0], fleet::Treatment::kAlongPlan);
  const planning::Plan standing = fleet::standing_plan(left.problem.start_q, 3.0);
  std::string why;
  // Left's plan starts at 7 s: from then on right is home, clear of it.
  EXPECT_FALSE(neighbours_
                   ->blocker(d, 7'000'000, *left.problem.model, standing, 0.0, 0.0, 0.0, why)
                   .has_value())
      << why;
  // From no state, left stood at its start while right reached into it, 2 s before knot 0.
  const std::optional<fleet::Blocker> b =
      neighbours_->blocker(d, 7'000'000, *left.problem.model, standing, 0.0, 0.0,
                           -std::numeric_limits<double>::infinity(), why);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->treatment, fleet::Treatment::kAlongPlan);
  EXPECT_NE(why.find("overlap"), std::string::npos) << why;
  EXPECT_NE(why.find("at t = -"), std::string::npos) << why;
}

// A neighbour heard publishing plans but no states moves along them (its daemon plans its next
// one from where they have it): held still (as when it has gone silent), it stands where its
// latest plan has it at the own plan's start, not back where that plan started.
TEST_F(ReachingIntoLeftTest, HoldsANeighbourWithoutStatesWhereItsPlanHasIt) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));  // later than left's goal: lower
  send("RIGHT_PLAN", moving_plan(3, spec_.start_q, into));  // 5–6 s: ends reaching into left
  fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  d.treatment[0] = fleet::Treatment::kHeldAtState;  // as a silent neighbour is
  const auto held_at = [&](int64_t origin_utime, const Eigen::VectorXd& q) {
    std::vector<collision::Obstacle> obstacles;
    neighbours_->add_obstacles(d, origin_utime, obstacles);
    ASSERT_EQ(obstacles.size(), spec_.model->collision.size());
    const std::vector<fleet::NeighbourBody> at_q =
        fleet::bodies_at({"right", spec_.model}, q, Neighbours::kFirstObstacleId);
    for (std::size_t g = 0; g < obstacles.size(); ++g) {
      EXPECT_FALSE(obstacles[g].is_moving());
      EXPECT_TRUE(obstacles[g].pose.isApprox(at_q[g].obstacle.pose, 1e-12)) << "body " << g;
    }
  };
  held_at(4'000'000, spec_.start_q);  // before its plan starts: where it starts
  held_at(7'000'000, into);           // after it ended: where it ends
  const planning::Plan standing = fleet::standing_plan(left.problem.start_q);
  std::string why;
  EXPECT_FALSE(
      neighbours_->blocker(d, 4'000'000, *left.problem.model, standing, 0.0, 0.0, 0.0, why))
      << why;
  // Left's plan starting at 7 s runs into it; one starting at 4 s but waiting 3 s too.
  for (const auto& [origin, wait] : {std::pair{7'000'000, 0.0}, std::pair{4'000'000, 3.0}}) {
    const std::optional<fleet::Blocker> b =
        neighbours_->blocker(d, origin, *left.problem.model, standing, wait, 0.0, 0.0, why);
    ASSERT_TRUE(b.has_value()) << origin;
    EXPECT_EQ(b->treatment, fleet::Treatment::kHeldAtState);
    EXPECT_NE(why.find("overlap"), std::string::npos) << why;
  }
}

// A neighbour without states held still (as a silent one is) while it is under way, reaching
// into left only while it moves (5.3–5.7 s): a blocker that moves, waited for until its plan ends
// (6 s), after which it stands at its plan's end, clear. A robot with measured states is where
// they say: not "moving".
TEST_F(ReachingIntoLeftTest, WaitsForAHeldNeighbourUnderWayUntilItsPlanEnds) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));  // later than left's goal: lower
  plan_t out_and_back = moving_plan(3, spec_.start_q, spec_.start_q);
  for (std::size_t k = 4; k <= 6; ++k) {
    for (int j = 0; j < spec_.model->nq(); ++j) out_and_back.q[k][j] = into[j];
  }
  send("RIGHT_PLAN", out_and_back);
  fleet::Decision d = neighbours_->decide({2'000'000, ""}, true);
  d.treatment[0] = fleet::Treatment::kHeldAtState;  // as a silent neighbour is
  const planning::Plan standing = fleet::standing_plan(left.problem.start_q);
  std::string why;
  const std::optional<fleet::Blocker> b =
      neighbours_->blocker(d, 5'500'000, *left.problem.model, standing, 0.0, 0.0, 0.0, why);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->treatment, fleet::Treatment::kHeldAtState);
  EXPECT_TRUE(b->moving);
  EXPECT_NEAR(b->plan_end, 0.5, 1e-9);  // its plan ends at 6 s, 0.5 s after left's knot 0
  const fleet::Remedy r = fleet::remedy("LEFT", *b, 0.0, 3.0, "", why);
  ASSERT_EQ(r.kind, fleet::Remedy::Kind::kWait) << r.reason;
  EXPECT_NEAR(r.wait.wait, 0.5, 1e-9);
  EXPECT_FALSE(neighbours_->blocker(d, 5'500'000, *left.problem.model, standing, r.wait.wait,
                                    0.0, 0.0, why))
      << why;
  // Still blocked once its plan has ended: no second wait, a failure naming it.
  const fleet::Remedy after = fleet::remedy("LEFT", *b, 0.5, 3.0, "", why);
  EXPECT_EQ(after.kind, fleet::Remedy::Kind::kFail);
  EXPECT_NE(after.reason.find("held where its plan ends, even after waiting 0.500 s"),
            std::string::npos)
      << after.reason;
  // With a measured state it stands where the state says, not on its plan: nothing to wait for.
  robot_state_t state{};
  state.utime = 5'400'000;
  state.robot = spec_.model->name;
  state.num_joints = spec_.model->nq();
  for (int j = 0; j < spec_.model->nq(); ++j) state.joint_name.push_back(spec_.model->bodies[j].joint_name);
  state.position.assign(into.data(), into.data() + into.size());
  state.velocity.assign(into.size(), 0.0);
  send("RIGHT_STATE", state);
  const std::optional<fleet::Blocker> measured =
      neighbours_->blocker(d, 5'500'000, *left.problem.model, standing, 0.0, 0.0, 0.0, why);
  ASSERT_TRUE(measured.has_value());
  EXPECT_FALSE(measured->moving);
}

TEST_F(NeighboursTest, TriesARefusedGoalAgainOncePerNewPlanOfItsBlockerFollowingIt) {
  send("RIGHT_PLANNER_STATUS", heartbeat(3'000'000));  // later than left's goal: lower
  const fleet::PriorityKey own{2'000'000, ""};
  const planning::Plan at_right = fleet::standing_plan(spec_.start_q);
  std::string why;
  // Left's goal where right stands (its scene's start): refused, blocked by right held there.
  fleet::Decision d = neighbours_->decide(own, true);
  std::optional<fleet::Blocker> b =
      neighbours_->blocker(d, 4'000'000, *spec_.model, at_right, 0.0, 0.0, 0.0, why);
  ASSERT_TRUE(b.has_value());
  ASSERT_EQ(b->treatment, fleet::Treatment::kHeldAtState);
  neighbours_->planned(d, false, &*b);
  EXPECT_FALSE(neighbours_->decide(own, false).replan);

  for (int k = 1; k <= fleet::kMaxBlockedRetries; ++k) {
    send("RIGHT_PLAN", plan(k));  // right planned: try again, right moving along its plan
    d = neighbours_->decide(own, false);
    EXPECT_TRUE(d.replan) << d.reason;
    EXPECT_TRUE(d.retry);
    ASSERT_EQ(d.treatment[0], fleet::Treatment::kAlongPlan);
    b = neighbours_->blocker(d, 4'000'000, *spec_.model, at_right, 0.0, 0.0, 0.0, why);
    ASSERT_TRUE(b.has_value());
    EXPECT_EQ(b->treatment, fleet::Treatment::kAlongPlan);
    EXPECT_NEAR(b->plan_end, 2.0, 1e-9);  // starts 1 s after knot 0, lasts 1 s: a wait's end
    neighbours_->planned(d, false, &*b);  // refused again: only right's next plan is a retry
    // The heartbeat reports what the valid plan, of which there is none, was made around.
    EXPECT_EQ(neighbours_->summary(), "right: plan " + std::to_string(k) + ", held at its state");
    EXPECT_FALSE(neighbours_->decide(own, false).replan);
    send("RIGHT_PLAN_CURRENT", plan(k));  // the same plan sent again is nothing new
    EXPECT_FALSE(neighbours_->decide(own, false).replan);
  }
  send("RIGHT_PLAN", plan(10));  // the bound per goal
  EXPECT_FALSE(neighbours_->decide(own, false).replan);

  // A new goal starts the count again; a valid plan for it forgets the refusal.
  d = neighbours_->decide({2'500'000, ""}, true);
  neighbours_->planned(d, false, &*b);
  send("RIGHT_PLAN", plan(11));
  d = neighbours_->decide({2'500'000, ""}, false);
  EXPECT_TRUE(d.retry);
  neighbours_->planned(d, true, nullptr);
  EXPECT_EQ(neighbours_->summary(), "right: plan 11, followed");
  send("RIGHT_PLAN", plan(12));
  EXPECT_FALSE(neighbours_->decide({2'500'000, ""}, false).replan);
}

// A blocked by B, B by C, C by A: each where the next must go. A finds the cycle from the
// heartbeats' reasons, and only once it closes through A.
TEST_F(NeighboursTest, FindsADeadlockOfACycleOfRobotsEachBlockedByTheNext) {
  NeighbourSpec b = spec_, c = spec_;
  b.name = "b";
  b.channel_prefix = "B";
  c.name = "c";
  c.channel_prefix = "C";
  Neighbours three({b, c}, "A", NeighboursOptions{});
  three.subscribe(lcm_, [] {});
  planner_status_t hb = heartbeat(3'000'000);  // both later than A's goal: held at their states
  const auto blocked_by = [&](const std::string& channel, const std::string& name,
                              const std::string& prefix) {
    hb.message = fleet::blocked_reason(name, prefix, fleet::Treatment::kHeldAtState, 0, "x");
    send(channel, hb);
  };
  blocked_by("B_PLANNER_STATUS", "c", "C");
  EXPECT_TRUE(three.blocking_cycle("b").empty());  // C is not blocked
  blocked_by("C_PLANNER_STATUS", "b", "B");
  EXPECT_TRUE(three.blocking_cycle("b").empty());  // a cycle of B and C only
  three.take_changed();
  blocked_by("C_PLANNER_STATUS", "a", "A");
  EXPECT_TRUE(three.take_changed());  // it may close a cycle: look again
  EXPECT_EQ(three.blocking_cycle("b"), (std::vector<std::string>{"B", "C"}));
  EXPECT_EQ(three.blocking_cycle("c"), std::vector<std::string>{"C"});

  const fleet::Decision d = three.decide({2'000'000, ""}, true);
  std::string why;
  const std::optional<fleet::Blocker> found = three.blocker(
      d, 4'000'000, *spec_.model, fleet::standing_plan(spec_.start_q), 0.0, 0.0, 0.0, why);
  ASSERT_TRUE(found.has_value());
  EXPECT_TRUE(found->blocked_by_own);
  const fleet::Remedy r = fleet::remedy("A", *found, 0.0, 3.0, "", why);
  EXPECT_EQ(r.kind, fleet::Remedy::Kind::kDeadlock) << r.reason;
  three.unsubscribe(lcm_);
}

TEST(NeighbourOption, NeedsANameAndAScene) {
  EXPECT_THROW(neighbour_from_option("right"), std::invalid_argument);
  EXPECT_THROW(neighbour_from_option("=x.yaml"), std::invalid_argument);
  EXPECT_THROW(neighbour_from_option("right=x.yaml@"), std::invalid_argument);
  EXPECT_THROW(neighbour_from_option("right=/nonexistent/scene.yaml"), planning::SceneError);
  const NeighbourSpec s = neighbour_from_option("r=" + std::string(KINOGRAPH_SOURCE_DIR) +
                                                "/robots/scenes/iiwa_pair_right.yaml@ARM2");
  EXPECT_EQ(s.channel_prefix, "ARM2");
  EXPECT_NEAR(s.base.translation().x(), 1.3, 1e-12);
}

}  // namespace
}  // namespace kinograph::daemon
