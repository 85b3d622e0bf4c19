#!/usr/bin/env bash
# The loop closed, with real processes over UDP multicast in a private network namespace:
# kinographd, `kinograph execute` and `kinograph sim` (the iiwa desk scene with its 2 kg block),
# the simulator's states recorded by lcm-logger and judged by `kinograph check-states` with the
# validator's clearance world.
#  1. goal -> plan -> execution: the arm arrives within 1e-2 rad of the goal and comes to rest,
#     and the executed states never touch the desk, the floor or the arm itself; that executed
#     path passes through the ball of iiwa_desk_late_ball.yaml (about 2.2 s into the motion).
#  2. the same goal, and the ball appears while the arm moves: the replan joins the motion
#     (jump of the commanded q <= 1e-6 rad, q' <= 1e-4 rad/s at the take-over, as the executor
#     measures it) and the executed path clears the ball.
# The simulator runs 4x slower than the wall clock so that the planner's wall-clock latency is
# a quarter as long on the robot's clock: the take-over time is met on a loaded machine.
# Usage: closed_loop_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/integration/sim_lib.sh"
URL="udpm://239.255.76.67:7731?ttl=0&recv_buf_size=4194304"
BALL="$SRC/tests/integration/iiwa_desk_late_ball.yaml"
SLOWDOWN=4

# Starts the logger of IIWA_STATE into $1, the simulator, the daemon and the executor.
start_loop() {
  lcm-logger -f -c IIWA_STATE --lcm-url="$URL" "$1" >"$WORK/logger.log" 2>&1 &
  LOGGER=$!
  PIDS+=($LOGGER)
  start_sim "$URL" --slowdown $SLOWDOWN --start-utime 1000000
  for _ in $(seq 300); do [ -s "$1" ] && break; sleep 0.1; done
  [ -s "$1" ] || fail "lcm-logger records no states"
  start_kgd "$URL" --prefix IIWA --takeover-latency 0.3
  "$KG" execute "$SCENE" --prefix IIWA --lcm-url "$URL" >"$WORK/execute.log" 2>&1 &
  EXECUTOR=$!
  PIDS+=($EXECUTOR)
  wait_for_line "$WORK/execute.log" "kinograph execute: robot" || fail "executor did not start"
}
# The latest state's utime (robot clock).
robot_now() {
  "$PROBE" states --url "$URL" --channel IIWA_STATE --count 1 >"$WORK/now.out"
  value "$WORK/now.out" last_utime
}
# Waits until the arm rests at the goal, then stops the processes (the executor and the
# simulator print their summaries).
arrive_and_stop() {
  "$PROBE" wait-near --url "$URL" --channel IIWA_STATE --near "$GOAL" --tol 1e-2 --count 200 \
    --timeout 300 || fail "the arm did not arrive within 1e-2 rad of the goal"
  for p in $EXECUTOR $SIM $DAEMON $LOGGER; do kill -INT "$p"; done
  wait "$EXECUTOR" || fail "executor did not exit cleanly"
  wait "$SIM" || fail "sim did not exit cleanly"
  wait "$DAEMON" || true
  wait "$LOGGER" || true
  PIDS=()
}

echo "== 1: goal, plan, execution"
start_loop "$WORK/run1.lcmlog"
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime "$(robot_now)" \
  --wait 120 >"$WORK/goal1.out" || fail "goal 1 not answered with a valid plan"
arrive_and_stop
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
start_loop "$WORK/run2.lcmlog"
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime "$(robot_now)" \
  --wait 120 >"$WORK/goal2.out" || fail "goal 1 not answered with a valid plan"
# 0.2 s of motion on the robot's clock, then the ball.
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 40 >/dev/null
"$KG" send-obstacle --prefix IIWA --lcm-url "$URL" --id ball --shape sphere --size 0.05 \
  --position 0.5,0,0.75 --utime "$(robot_now)" --goal-id 1 --wait 120 \
  | tee "$WORK/replan.out" || fail "the replan is not valid"
arrive_and_stop
grep "takes over" "$WORK/execute.log" || true
summary=$(grep "kinograph execute:" "$WORK/execute.log")
echo "$summary"
switches=$(echo "$summary" | sed -n 's/.*; \([0-9]*\) take-overs from a plan.*/\1/p')
jq=$(echo "$summary" | sed -n 's/.*largest jump \([^ ]*\) rad, .*/\1/p')
jqd=$(echo "$summary" | sed -n 's/.*rad, \([^ ]*\) rad\/s.*/\1/p')
[ "$switches" -ge 1 ] || fail "the replan never took over"
at_most "$jq" 1e-6 || fail "the take-over jumps $jq rad"
at_most "$jqd" 1e-4 || fail "the take-over jumps $jqd rad/s"
grep -q "after its take-over" "$WORK/daemon.log" && fail "the replan came after its take-over time"
"$KG" check-states "$WORK/run2.lcmlog" --scene "$SCENE" --change "$BALL" | tee "$WORK/run2.out"
at_most 0 "$(value "$WORK/run2.out" min_clearance)" || fail "the executed path hits the ball"
at_most "$(value "$WORK/run2.out" final_goal_error)" 1e-2 || fail "final state not at the goal"
grep "kinograph sim: tracking" "$WORK/sim.log"
echo "2 passed, 0 failed"
