#!/usr/bin/env bash
# Waiting for a neighbour (docs/multi_robot.md): two planar RR arms in one plane, one kinographd
# each over real UDP multicast in a private network namespace. 'sweep' (earlier goal, higher
# priority) swings over the top in 3 s; 'hanging', from the ceiling beside it, must put its tip
# where 'sweep' passes upright halfway, in 1 s: whatever it does within its own 1 s it would stand
# there when 'sweep' passes (tests/integration/fleet_rr_sweep.yaml, fleet_rr_hanging.yaml). Both
# get measured states stamped on one robot clock, so every plan time is exact. Checked: 'hanging'
# holds its start until the sweep has ended, its plan starts exactly 3 s after the sweep's, says
# it waited in the plan and the heartbeat, and both plans validate and keep clear together; with
# --no-neighbour-wait the same goal is answered with the failure, naming 'sweep'.
# Usage: fleet_wait_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7713?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

SWEEP="$SRC/tests/integration/fleet_rr_sweep.yaml"
HANGING="$SRC/tests/integration/fleet_rr_hanging.yaml"
# send_states UTIME: both arms at their starts at UTIME on the robots' clock.
send_states() {
  "$KG" send-state --prefix SWEEP --lcm-url "$URL" --scene "$SWEEP" --q 0.6,0 --utime "$1"
  "$KG" send-state --prefix HANGING --lcm-url "$URL" --scene "$HANGING" --q 0,0 --utime "$1"
}
# start_utime FILE: the plan file's start on the common clock (µs).
start_utime() { sed -n 's/^ *"start_utime": \([0-9]*\).*/\1/p' "$1"; }

start_robot sweep "$SWEEP" --neighbour "hanging=$HANGING"
start_robot hanging "$HANGING" --neighbour "sweep=$SWEEP"

# 1. With waiting (the default): 'hanging' plans from the state 3 s later.
T=1000000000000
send_states $T
watch --robot "SWEEP=$SWEEP" --robot "HANGING=$HANGING"
send_goal sweep 1 "-1.0,0" "$SWEEP" $((T + 100))
send_goal hanging 1 "-0.767,0" "$HANGING" $((T + 200))
await_settled
check_plans "sweep=$SWEEP" "hanging=$HANGING"
WAITS="starts 3.000 s late: waits for neighbour 'sweep''s plan to end"
grep -q "$WAITS" "$WORK/hanging_goal_1.out" \
  || fail "hanging's plan does not say it waits: $(cat "$WORK/hanging_goal_1.out")"
[ "$(start_utime "$WORK/sweep.json")" = "$T" ] || fail "sweep's plan does not start at the state"
[ "$(start_utime "$WORK/hanging.json")" = "$((T + 3000000))" ] \
  || fail "hanging's plan starts at $(start_utime "$WORK/hanging.json"), not when sweep's ends"
"$PROBE" heartbeat --url "$URL" --prefix HANGING --message "waits for neighbour 'sweep'" \
  --timeout 30 >"$WORK/beat.out" 2>&1 || fail "hanging's heartbeat does not say it waits"
kill -TERM "${PID[hanging]}"
wait "${PID[hanging]}" || fail "hanging did not stop cleanly"
unset 'PID[hanging]'
grep -q "1 waiting for one" "$WORK/hanging.log" || fail "hanging did not count its wait"
echo "PASS: the yielding arm waits"

# 2. The same problem with 'hanging' told not to wait: its goal is answered with the failure.
start_robot hanging "$HANGING" --neighbour "sweep=$SWEEP" --no-neighbour-wait
T=$((T + 10000000))
send_states $T
send_goal sweep 2 "-1.0,0" "$SWEEP" $((T + 100))
"$KG" send-goal --prefix HANGING --lcm-url "$URL" --id 1 --q=-0.767,0 --wait 120 \
  --utime $((T + 200)) >"$WORK/no_wait.out" 2>&1 && fail "hanging planned without waiting"
BLOCKED="FAILED (blocked by neighbour 'sweep' \[SWEEP\], moving along its plan: "
grep -q "$BLOCKED.*(not waiting: waiting is off)" "$WORK/no_wait.out" \
  || fail "the failure does not name sweep: $(cat "$WORK/no_wait.out")"
echo "PASS: without waiting the goal fails, naming the neighbour"
echo "2 passed, 0 failed"
