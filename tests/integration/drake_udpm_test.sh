#!/usr/bin/env bash
# Drake's messages over real UDP multicast in a private network namespace: the simulated iiwa
# publishes Drake's lcmt_iiwa_status on IIWA_STATUS, kinographd (whose own state channel nobody
# feeds) takes it as the robot's state and publishes its plan also as Drake's lcmt_robot_plan,
# which lcm_probe checks against the fingerprint of Drake's layout and reads: knot times within
# the plan, joint names, the first knot at the measured state and the last at the goal. A
# malformed status is refused and the daemon keeps serving.
# Usage: drake_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/integration/sim_lib.sh"
URL="udpm://239.255.76.67:7722?ttl=0&recv_buf_size=4194304"

start_sim "$URL" --iiwa-status-channel IIWA_STATUS
start_kgd "$URL" --prefix KG --iiwa-status-channel IIWA_STATUS \
  --drake-plan-channel COMMITTED_ROBOT_PLAN
"$KG" send-raw IIWA_STATUS --text "not a status" --lcm-url "$URL"
wait_for_line "$WORK/daemon.log" "malformed lcmt_iiwa_status" || fail "bad status not reported"

"$PROBE" drake-plan --url "$URL" --channel COMMITTED_ROBOT_PLAN --timeout 120 >"$WORK/drake.out" &
PROBE_PID=$!
PIDS+=($PROBE_PID)
wait_for_line "$WORK/drake.out" ready || fail "probe did not start"
"$KG" send-goal --prefix KG --lcm-url "$URL" --id 1 --q "$GOAL" --wait 120 | tee "$WORK/plan.out" \
  || fail "goal not planned"
grep -q "clock robot" "$WORK/plan.out" || fail "the plan did not start from the IIWA_STATUS state"
wait "$PROBE_PID" || fail "no Drake robot plan: $(cat "$WORK/drake.out")"
cat "$WORK/drake.out"
grep -q "is Drake's lcmt_robot_plan" "$WORK/drake.out" || fail "wrong fingerprint"
start=$(sed -n 's/.*starts at \([0-9]*\) us.*/\1/p' "$WORK/plan.out")
[ "$(value "$WORK/drake.out" utime)" = "$start" ] || fail "Drake plan utime is not the plan's start"
[ "$(value "$WORK/drake.out" num_states)" -eq 31 ] || fail "expected the scene's 31 knots"
[ "$(value "$WORK/drake.out" first_knot_utime)" -eq 0 ] || fail "first knot not at 0"
[ "$(value "$WORK/drake.out" last_knot_utime)" -eq 3000000 ] || fail "last knot not at the 3 s horizon"
[ "$(value "$WORK/drake.out" joint_name_0)" = iiwa_joint_1 ] || fail "joint names missing"
# Each knot's positions against the start (held by the sim) and the goal.
close() {
  awk -v line="$(grep "^$1 " "$WORK/drake.out")" -v ref="$2" -v tol="$3" 'BEGIN {
    n = split(line, q, " "); split(ref, r, ",");
    for (i = 2; i <= n; ++i) { d = q[i] - r[i - 1]; if (d < 0) d = -d; if (d > tol) exit 1 }
    exit (n != 8) }'
}
close first_q "$START" 1e-5 || fail "first knot is not the measured state"
close last_q "$GOAL" 1e-3 || fail "last knot is not the goal"
echo "1 passed, 0 failed"
