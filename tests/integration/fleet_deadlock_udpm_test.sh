#!/usr/bin/env bash
# A deadlock (docs/multi_robot.md): two planar RR arms in one plane, 1 m apart, both upright,
# must swap sides, each goal through where the other stands (tests/integration/
# fleet_rr_swap_left.yaml, _right.yaml); one kinographd each over real UDP multicast in a private
# network namespace. 'left' (earlier goal) holds 'right' at its state and fails, blocked by it;
# 'right', holding 'left' where it stands, finds left blocked by itself and answers with a
# deadlock naming both; 'left' then answers its goal again as that deadlock. Checked: both
# answers say deadlock and name both robots, and neither daemon publishes a plan afterwards
# (no replanning loop).
# Usage: fleet_deadlock_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7714?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

LEFT="$SRC/tests/integration/fleet_rr_swap_left.yaml"
RIGHT="$SRC/tests/integration/fleet_rr_swap_right.yaml"
start_robot left "$LEFT" --neighbour "right=$RIGHT"
start_robot right "$RIGHT" --neighbour "left=$LEFT"

# goal_fails NAME UTIME: the scene's goal, answered with a failure; the answer in $WORK/NAME.out.
goal_fails() {
  "$KG" send-goal --prefix "${1^^}" --lcm-url "$URL" --id 1 --q 1.2,0 --wait 120 --utime "$2" \
    >"$WORK/$1.out" 2>&1 && fail "$1's goal was planned: $(cat "$WORK/$1.out")"
  grep -q "FAILED" "$WORK/$1.out" || fail "$1's goal not answered: $(cat "$WORK/$1.out")"
}
T=$(date +%s%6N)
goal_fails left $T
grep -q "blocked by neighbour 'right' \[RIGHT\], held at its state" "$WORK/left.out" \
  || fail "left's failure does not name right as its blocker: $(cat "$WORK/left.out")"
goal_fails right $((T + 1000000))
grep -q "FAILED (deadlock with neighbour 'left' \[LEFT\]: robots 'RIGHT' and 'LEFT'" \
  "$WORK/right.out" || fail "right's failure is not the deadlock: $(cat "$WORK/right.out")"
echo "PASS: the second robot reports the deadlock"

# Left answers its goal again as the deadlock; then both stay quiet for ten heartbeats each.
"$PROBE" heartbeat --url "$URL" --prefix LEFT --message "deadlock with neighbour 'right' [RIGHT]" \
  --steady 10 --timeout 60 >"$WORK/left_beat.out" 2>&1 \
  || fail "left does not report the deadlock, or replans: $(cat "$WORK/left_beat.out")"
grep -q "robots 'LEFT' and 'RIGHT'" "$WORK/left_beat.out" || fail "left's deadlock names not both"
"$PROBE" heartbeat --url "$URL" --prefix RIGHT --message "deadlock with neighbour 'left'" \
  --steady 10 --timeout 60 >"$WORK/right_beat.out" 2>&1 \
  || fail "right replans after the deadlock: $(cat "$WORK/right_beat.out")"
cat "$WORK/left_beat.out" "$WORK/right_beat.out"
echo "PASS: both report the deadlock, and neither replans"
echo "2 passed, 0 failed"
