#!/usr/bin/env bash
# A publish that LCM refuses is not silent: kinographd is given a Drake plan channel longer
# than LCM's 63-character limit for channel names, so every valid plan's copy on it fails to
# send over udpm. The goal is still answered on RR_PLAN, the failure is logged as an error, and
# the heartbeat's message counts it.
# Usage: publish_failure_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7713?ttl=0&recv_buf_size=4194304"
LONG=$(printf 'C%.0s' $(seq 70))

"$KGD" "$SRC/tests/integration/rr_daemon.yaml" --prefix RR --lcm-url "$URL" --status-period 0.2 \
  --drake-plan-channel "$LONG" >"$WORK/daemon.log" 2>&1 &
DAEMON=$!
PIDS+=($DAEMON)
wait_for_line "$WORK/daemon.log" "on channels RR_" || fail "daemon did not start"
"$STORM" --url "$URL" --prefix RR --goals 1 --answer-timeout 120 \
  --heartbeat-text "1 publishes failed since start, the last on $LONG" >"$WORK/storm.out" 2>&1 \
  || { cat "$WORK/storm.out"; fail "the goal was not answered or the heartbeat did not count"; }
cat "$WORK/storm.out"
grep -q '"planned": 1' "$WORK/storm.out" || fail "the goal was not planned"
wait_for_line "$WORK/daemon.log" "publishing lcmt_robot_plan on $LONG failed" \
  || fail "the failed publish was not logged"
grep -q "\[error\] publishing lcmt_robot_plan on $LONG failed" "$WORK/daemon.log" \
  || fail "the failed publish was not logged as an error"
echo "1 passed, 0 failed"
