#!/usr/bin/env bash
# Two kinographd on the same channel prefix both answer every goal, with colliding plan ids:
# each reads its own status channel back and reports the other's heartbeats, in its log and in
# its own heartbeat's message. A daemon alone reports nothing of the kind.
# Usage: second_daemon_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7714?ttl=0&recv_buf_size=4194304"
SCENE="$SRC/tests/integration/rr_daemon.yaml"

start_daemon "$SCENE" "$URL" "$WORK/daemon1.log"
# The first daemon's own heartbeats (period 0.2 s) are read back while it serves a goal alone.
"$STORM" --url "$URL" --prefix RR --goals 1 --answer-timeout 120 >"$WORK/alone.out" 2>&1 \
  || { cat "$WORK/alone.out"; fail "the lone daemon did not answer"; }
grep -q "another planner daemon" "$WORK/daemon1.log" && fail "a lone daemon reported another"
start_daemon "$SCENE" "$URL" "$WORK/daemon2.log"
wait_for_line "$WORK/daemon1.log" "another planner daemon publishes on RR_PLANNER_STATUS" \
  || fail "the first daemon did not report the second"
wait_for_line "$WORK/daemon2.log" "another planner daemon publishes on RR_PLANNER_STATUS" \
  || fail "the second daemon did not report the first"
"$STORM" --url "$URL" --prefix RR --goals 1 --first-id 2 --answer-timeout 120 \
  --heartbeat-text "another planner daemon publishes on RR_PLANNER_STATUS" >"$WORK/two.out" 2>&1 \
  || { cat "$WORK/two.out"; fail "no heartbeat reported the second daemon"; }
echo "1 passed, 0 failed"
