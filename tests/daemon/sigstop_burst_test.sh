#!/usr/bin/env bash
# A stalled daemon loses no goal: kinographd is stopped (SIGSTOP, standing in for any stall),
# 40 goals are sent over real UDP multicast, the daemon is resumed, and every goal must be
# answered exactly once, each planned or SUPERSEDED, and the newest (139) planned and valid.
# LCM's default queue of 30 messages per subscription would drop the 10 newest here. How many
# are planned is not fixed: the planner may take up a goal while the LCM thread is still
# draining the socket, so a goal from the middle of the burst can be planned as well.
# Usage: sigstop_burst_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7711?ttl=0&recv_buf_size=4194304"

start_daemon "$SRC/tests/integration/rr_daemon.yaml" "$URL" "$WORK/daemon.log"
kill -STOP "$DAEMON"
"$STORM" --url "$URL" --prefix RR --goals 40 --first-id 100 --answer-timeout 120 \
  --json "$WORK/burst.json" >"$WORK/storm.out" 2>&1 &
CLIENT=$!
# The client says "sent" once its goals have looped back to it, i.e. are in the daemon's socket.
wait_for_line "$WORK/storm.out" "sent 40 goals" || fail "client did not send"
kill -CONT "$DAEMON"
wait "$CLIENT" || { cat "$WORK/storm.out"; fail "not every goal answered as it should be"; }
cat "$WORK/storm.out"
field() { sed -n "s/^{[^{]*\"$1\": \([0-9]*\).*/\1/p" "$WORK/burst.json"; }
PLANNED=$(field planned)
SUPERSEDED=$(field superseded)
[ "$(field answered)" = 40 ] || fail "not all 40 goals answered"
[ "$PLANNED" -ge 1 ] && [ $((PLANNED + SUPERSEDED)) = 40 ] \
  || fail "expected every goal planned or superseded, got $PLANNED planned, $SUPERSEDED superseded"
grep -q '"other_status": 0' "$WORK/burst.json" || fail "a goal was answered neither way"
grep -q "\"heartbeat\": {\"received\": 40, \"answered\": 40, \"superseded\": $SUPERSEDED, \"dropped\": 0}" \
  "$WORK/burst.json" || fail "heartbeat does not account for the 40 goals"
grep -q "goal 139: plan" "$WORK/daemon.log" || fail "goal 139 (the newest) not planned"
echo "1 passed, 0 failed"
