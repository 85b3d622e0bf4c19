#!/usr/bin/env bash
# Receding horizon over real UDP multicast in a private network namespace: kinographd,
# `kinograph execute` and `kinograph sim` (iiwa desk scene, states at 200 Hz of its clock) while
# the goal moves slowly: a new goal every 0.1 s of the robot's clock for 5 s (50 goals, the base
# joint 0.004 rad further each time), each stamped with the latest state's time. Every goal is
# answered (a plan or SUPERSEDED, read back from the recorded IIWA_PLAN), every take-over the
# executor makes is continuous (<= 1e-6 rad, <= 1e-4 rad/s), and the arm ends at the last goal.
# The simulator runs 10x slower than the wall clock so that the planner's wall-clock latency
# fits in --takeover-latency on the robot's clock on a loaded machine; the goals start once the
# executor follows the first plan.
# Usage: receding_horizon_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
URL="udpm://239.255.76.67:7732?ttl=0&recv_buf_size=4194304"
source "$SRC/tests/integration/loop_lib.sh"
GOALS=50

start_loop "$WORK/run.lcmlog" 'IIWA_STATE|IIWA_PLAN' --slowdown 10 --start-utime 1000000
stream_goals $GOALS
arrive_and_stop "$(goal_q $GOALS)"
check_takeovers 1
"$KG" log-plans "$WORK/run.lcmlog" --channel IIWA_PLAN --scene "$SCENE" --out-dir "$WORK/plans" \
  >"$WORK/plans.out"
answered=$(grep -o "^plan [0-9]* for goal [0-9]*" "$WORK/plans.out" | awk '{ print $5 }' | sort -un | wc -l)
planned=$(grep -c "for goal [0-9]*: SUCCESS" "$WORK/plans.out" || true)
superseded=$(grep -c "for goal [0-9]*: SUPERSEDED" "$WORK/plans.out" || true)
failed=$(grep "^plan [0-9]* for goal" "$WORK/plans.out" | grep -vc "SUCCESS\|SUPERSEDED" || true)
echo "goals answered $answered of $GOALS: $planned plans, $superseded superseded, $failed failed"
[ "$answered" -eq $GOALS ] || fail "$answered of $GOALS goals answered"
[ "$failed" -eq 0 ] || fail "$failed goals answered with a failure: $(grep -v "SUCCESS\|SUPERSEDED" "$WORK/plans.out" | head)"
grep -q "for goal $GOALS: SUCCESS" "$WORK/plans.out" || fail "the last goal was not planned"
"$KG" check-states "$WORK/run.lcmlog" --scene "$SCENE" --goal "$(goal_q $GOALS)" | tee "$WORK/run.out"
at_most 0 "$(value "$WORK/run.out" min_clearance)" || fail "the executed path collides"
at_most "$(value "$WORK/run.out" final_goal_error)" 1e-2 || fail "final state not at the last goal"
grep "kinograph sim: tracking" "$WORK/sim.log"
echo "1 passed, 0 failed"
