#!/usr/bin/env bash
# The loop closed, with real processes over UDP multicast in a private network namespace:
# kinographd, `kinograph execute` and `kinograph sim` (the iiwa desk scene with its 2 kg block),
# the simulator's states recorded by lcm-logger and judged by `kinograph check-states` with the
# validator's clearance world.
#  1. goal -> plan -> execution: the arm arrives within 1e-2 rad of the goal and comes to rest,
#     and the executed states never touch the desk, the floor or the arm itself; that executed
#     path passes through the ball of iiwa_desk_late_ball.yaml (about 1.8 s into the motion).
#  2. the same goal, and the ball appears while the arm moves: the replan joins the motion
#     (jump of the commanded q <= 1e-6 rad, q' <= 1e-4 rad/s at the take-over, as the executor
#     measures it) and the executed path clears the ball.
# The simulator runs 10x slower than the wall clock (sim time: plans are stamped on its clock),
# so that the planner's wall-clock latency is a tenth as long on the robot's clock and the
# take-over time (0.5 s after the state, loop_lib.sh) is met on a loaded machine.
# Usage: closed_loop_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
URL="udpm://239.255.76.67:7731?ttl=0&recv_buf_size=4194304"
source "$SRC/tests/integration/loop_lib.sh"
BALL="$SRC/robots/scenes/changes/iiwa_desk_late_ball.yaml"

echo "== 1: goal, plan, execution, the simulator 10x slower than the wall clock from 5 s"
start_loop "$WORK/run1.lcmlog" IIWA_STATE --slowdown 10 --start-utime 5000000
now=$(robot_now)
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime "$now" \
  --wait 120 | tee "$WORK/goal1.out" || fail "goal 1 not answered with a valid plan"
grep -q "clock robot" "$WORK/goal1.out" || fail "the plan is not on the robot's clock"
start=$(sed -n 's/.*starts at \([0-9]*\) us.*/\1/p' "$WORK/goal1.out")
[ "$start" -ge "$now" ] && [ "$start" -le $((now + 10000000)) ] \
  || fail "plan starts at $start us, not on the sim's clock (at $now us)"
arrive_and_stop "$GOAL"
"$KG" check-states "$WORK/run1.lcmlog" --scene "$SCENE" | tee "$WORK/run1.out"
at_most "$(value "$WORK/run1.out" final_goal_error)" 1e-2 || fail "final state not at the goal"
at_most "$(value "$WORK/run1.out" final_speed)" 1e-3 || fail "the arm is not at rest"
at_most 0 "$(value "$WORK/run1.out" min_clearance)" || fail "the executed path collides"
"$KG" check-states "$WORK/run1.lcmlog" --scene "$SCENE" --change "$BALL" >"$WORK/run1_ball.out"
at_most "$(value "$WORK/run1_ball.out" min_clearance)" 0 \
  || fail "the ball would not be in the executed path's way: $(cat "$WORK/run1_ball.out")"
grep "kinograph execute:" "$WORK/execute.log"
grep "kinograph sim: tracking" "$WORK/sim.log"

echo "== 2: the ball appears while the arm moves"
start_loop "$WORK/run2.lcmlog" IIWA_STATE --slowdown 10 --start-utime 1000000
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime "$(robot_now)" \
  --wait 120 >"$WORK/goal2.out" || fail "goal 1 not answered with a valid plan"
# 0.2 s of motion on the robot's clock, then the ball.
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 40 >/dev/null
"$KG" send-obstacle --prefix IIWA --lcm-url "$URL" --id ball --shape sphere --size 0.05 \
  --position 0.25,0.5,0.6 --utime "$(robot_now)" --goal-id 1 --wait 120 \
  | tee "$WORK/replan.out" || fail "the replan is not valid"
arrive_and_stop "$GOAL"
grep "takes over" "$WORK/execute.log" || true
check_takeovers 1
"$KG" check-states "$WORK/run2.lcmlog" --scene "$SCENE" --change "$BALL" | tee "$WORK/run2.out"
at_most 0 "$(value "$WORK/run2.out" min_clearance)" || fail "the executed path hits the ball"
at_most "$(value "$WORK/run2.out" final_goal_error)" 1e-2 || fail "final state not at the goal"
grep "kinograph sim: tracking" "$WORK/sim.log"
echo "2 passed, 0 failed"
