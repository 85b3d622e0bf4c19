#!/usr/bin/env bash
# Two iiwa arms facing each other across a table with crossing goals, one kinographd each, over
# real UDP multicast in a private network namespace: each plans around the other under the
# coordination rule (docs/multi_robot.md). Checked: both plans validate and, checked together at
# and between the knots, keep clear; then left's goal moves keeping its priority and right
# replans around left's new plan from where its own plan has it, incrementally (its Bayes tree
# shifted to that knot, only the changed factors replaced), still clear; a later goal of left's
# makes left
# yield to right; then right is killed, left reports it silent, and the restarted right is
# picked up again.
# Usage: fleet_pair_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7711?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

LEFT="$SCENES/iiwa_pair_left.yaml"
RIGHT="$SCENES/iiwa_pair_right.yaml"
start_robot left "$LEFT" --neighbour "right=$RIGHT"
start_robot right "$RIGHT" --neighbour "left=$LEFT"

# 1. Crossing goals: left's first (it has priority), then right's, planned around left's plan.
watch --robot "LEFT=$LEFT" --robot "RIGHT=$RIGHT"
LEFT_GOAL_UTIME=$(date +%s%6N)
send_goal left 1 "-0.6,0.7,0,-1.3,0,0.8,0" "$LEFT" "$LEFT_GOAL_UTIME"
send_goal right 1 "-0.6,0.7,0,-1.3,0,0.8,0" "$RIGHT"
await_settled
grep -q "neighbours: right: [^;]*held at its state" "$WORK/probe.out" \
  || fail "left (higher priority) does not hold right at its state"
cp "$WORK/left.json" "$WORK/first_left.json"
cp "$WORK/right.json" "$WORK/first_right.json"

# 2. Left's goal moves, keeping its priority (the same goal time), while both arms move (sent
# at once; the first plans are checked meanwhile): left replans for its own goal, right replans
# around left's new plan. Without states each robot is where its plan in force has it: the
# replan starts at that plan's next knot, on the same Bayes tree. Where right stands then
# depends on when the goal comes; if it is in the way, left waits for right's plan to end (a
# lower robot already under way), so the outcome does not.
watch --robot "LEFT=$LEFT" --robot "RIGHT=$RIGHT" --newer "LEFT=$(current_plan LEFT)" \
  --newer "RIGHT=$(current_plan RIGHT)"
send_goal left 2 "-0.4,0.6,0,-1.4,0,0.8,0" "$LEFT" "$LEFT_GOAL_UTIME"
check_plans "first_left=$LEFT" "first_right=$RIGHT"
echo "PASS: crossing goals"
await_settled
check_plans "left=$(with_goal "$LEFT" "-0.4,0.6,0,-1.4,0,0.8,0" left2)" "right=$RIGHT"
grep -q "^RIGHT: .* [1-9][0-9]* neighbour replans" "$WORK/probe.out" \
  || fail "right did not count a neighbour replan"
grep -q "^RIGHT: plan [0-9]* (incremental" "$WORK/probe.out" \
  || fail "right's replan around left's new plan was not incremental"
grep -q "iDFGP: shifted [0-9]* knots" "$WORK/right.log" \
  || fail "right's replan did not go on from its plan's knots on the same tree"
echo "PASS: a neighbour's goal moved"

# 3. A later goal of left's makes it yield: it plans around right's plan, right keeps its own.
watch --robot "LEFT=$LEFT" --robot "RIGHT=$RIGHT" --newer "LEFT=$(current_plan LEFT)"
send_goal left 3 "-0.6,0.7,0,-1.3,0,0.8,0" "$LEFT"
await_settled
check_plans "left=$LEFT" "right=$RIGHT"
grep -q "^LEFT: .*neighbours: right: plan [0-9]*, followed" "$WORK/probe.out" \
  || fail "left (now lower priority) does not follow right's plan"
echo "PASS: a later goal yields"

# 4. Right killed and restarted: left sees it silent (held at its last state), then picks it up.
kill -KILL "${PID[right]}"
wait "${PID[right]}" 2>/dev/null || true
unset 'PID[right]'
"$PROBE" heartbeat --url "$URL" --prefix LEFT --contains "right: silent" --timeout 60 \
  >"$WORK/silent.out" 2>&1 || fail "left does not report right silent: $(cat "$WORK/silent.out")"
grep -q "held at its last state" "$WORK/silent.out" || fail "silent right is not held still"
watch --robot "LEFT=$LEFT" --robot "RIGHT=$RIGHT"
start_robot right "$RIGHT" --neighbour "left=$LEFT"
send_goal right 2 "0.6,0.7,0,-1.3,0,0.8,0" "$RIGHT"
await_settled
check_plans "left=$LEFT" "right=$(with_goal "$RIGHT" "0.6,0.7,0,-1.3,0,0.8,0" right2)"
grep -q "^RIGHT: .*neighbours: left: plan [0-9]*, followed" "$WORK/probe.out" \
  || fail "the restarted right does not follow left's current plan"
echo "PASS: a neighbour restarted"
echo "4 passed, 0 failed"
