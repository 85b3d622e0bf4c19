#!/usr/bin/env bash
# End to end over real UDP multicast, inside a private network namespace (nothing leaves this
# machine's loopback): kinographd serves goals and obstacle changes sent by the CLI, rejects
# malformed bytes and keeps serving, lcm-logger records the session, and lcm-logplayer replays
# its goals into a fresh daemon, which answers them again.
# Usage: daemon_lcm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"

KG="$BUILD/tools/kinograph"
KGD="$BUILD/daemon/kinographd"
SCENE="$SRC/tests/integration/rr_daemon.yaml"
URL="udpm://239.255.76.67:7701?ttl=0&recv_buf_size=4194304"
URL2="udpm://239.255.76.67:7702?ttl=0&recv_buf_size=4194304"
WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; echo "--- daemon log"; cat "$WORK"/daemon*.log || true; exit 1; }

# Starts a daemon on URL $1 logging to $2 and waits (bounded) until it serves.
start_daemon() {
  "$KGD" "$SCENE" --prefix RR --lcm-url "$1" --status-period 0.2 >"$2" 2>&1 &
  PIDS+=($!)
  for _ in $(seq 100); do grep -q "on channels RR_" "$2" && return 0; sleep 0.1; done
  fail "daemon did not start"
}

# Waits (bounded) until the lcm-logger on URL $1 writing $2 has recorded a probe message: it
# is subscribed, so nothing sent from now on is missed.
logger_ready() {
  for _ in $(seq 100); do
    "$KG" send-raw RR_LOGGER_PROBE --text probe --lcm-url "$1" >/dev/null
    grep -aq RR_LOGGER_PROBE "$2" 2>/dev/null && return 0
    sleep 0.1
  done
  fail "lcm-logger writing $2 did not start"
}

# Waits (bounded) until the log $1, written by the logger on URL $3, holds an answer log-plans
# reports as matching $2, so the logger is stopped only once the plan is written. lcm-logger
# flushes its file when a message arrives, so each try sends it a probe: without traffic (the
# daemon stopped) the last plan would stay in its buffer.
logged_answer() {
  for _ in $(seq 300); do
    "$KG" send-raw RR_LOGGER_PROBE --text probe --lcm-url "$3" >/dev/null
    rm -rf "$WORK/snapshot"
    cp "$1" "$WORK/snapshot.lcmlog"
    # Into a file, not a pipe: grep -q leaving early would end log-plans by SIGPIPE, and
    # pipefail would then count a match as a miss.
    "$KG" log-plans "$WORK/snapshot.lcmlog" --channel RR_PLAN --scene "$SCENE" \
      --out-dir "$WORK/snapshot" >"$WORK/snapshot.txt" 2>/dev/null || true
    grep -Eq "$2" "$WORK/snapshot.txt" && return 0
    sleep 0.1
  done
  fail "no answer matching '$2' in $1: $(cat "$WORK/snapshot.txt")"
}

# lcm-logger 1.3.1 lists -l in its help but rejects it: the long option works.
lcm-logger -f --lcm-url="$URL" "$WORK/session.lcmlog" >"$WORK/logger.log" 2>&1 &
LOGGER=$!
PIDS+=($LOGGER)
logger_ready "$URL" "$WORK/session.lcmlog"
start_daemon "$URL" "$WORK/daemon1.log"
DAEMON=${PIDS[-1]}

"$KG" send-goal --prefix RR --lcm-url "$URL" --id 1 --q 0.8,-0.4 --wait 60 \
  --scene "$SCENE" --out "$WORK/goal1.json" || fail "goal 1 not answered with a valid plan"
test -s "$WORK/goal1.json" || fail "plan JSON not written"

"$KG" send-obstacle --prefix RR --lcm-url "$URL" --id ball --shape sphere --size 0.05 \
  --position 0,0,1.85 --goal-id 1 --wait 60 || fail "obstacle replan of goal 1 failed"

"$KG" send-raw RR_GOAL --text "definitely not a goal_t" --lcm-url "$URL"
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 2 --q 0.3,0.3 --wait 60 \
  || fail "daemon stopped serving after a malformed message"
grep -q "malformed goal_t" "$WORK/daemon1.log" || fail "malformed goal not reported"

"$KG" send-goal --prefix RR --lcm-url "$URL" --id 3 --q 0.3 --wait 30 && fail "bad goal accepted"
grep -q "num_joints is 1" "$WORK/daemon1.log" || fail "wrong joint count not reported"

# Goals by joint name (goal_v2_t), in any order; a name the robot lacks is refused by name.
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 4 --joint joint2=0.3 --joint joint1=pi/10 \
  --wait 60 | tee "$WORK/goal4.txt" || fail "goal 4 (by joint name) not answered with a valid plan"
grep -q "goal_v2_t" "$WORK/goal4.txt" || fail "goal 4 was not sent as a goal_v2_t"
set +e
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 5 --joint joint1=0.3 --joint elbow=1 --wait 30
code=$?
set -e
[ "$code" -eq 2 ] || fail "goal 5 naming joint elbow: exit $code, expected 2 (invalid plan)"
grep -q '"elbow" is not a joint of rr' "$WORK/daemon1.log" || fail "unknown joint not named"

kill -TERM "$DAEMON"
wait "$DAEMON" || fail "daemon did not exit cleanly on SIGTERM"
logged_answer "$WORK/session.lcmlog" "for goal 5: " "$URL"
kill -INT "$LOGGER"
wait "$LOGGER" || true

"$KG" log-plans "$WORK/session.lcmlog" --channel RR_PLAN --scene "$SCENE" --out-dir "$WORK/plans" \
  | tee "$WORK/log-plans.txt"
n=$(ls "$WORK/plans" | wc -l)
[ "$n" -ge 3 ] || fail "expected >= 3 plans in the log, found $n"
grep -q "for goal 3: INVALID_GOAL" "$WORK/log-plans.txt" || fail "goal 3 not answered INVALID_GOAL"

# Replay the recorded goals and obstacles into a fresh daemon; it must answer them again. At the
# recorded pace a busy machine can still let goal 2 arrive before goal 1 is taken up, and the
# daemon then rightly answers goal 1 SUPERSEDED: answered either way, the newest planned.
lcm-logger -f --lcm-url="$URL2" "$WORK/replay.lcmlog" >/dev/null 2>&1 &
LOGGER2=$!
PIDS+=($LOGGER2)
logger_ready "$URL2" "$WORK/replay.lcmlog"
start_daemon "$URL2" "$WORK/daemon2.log"
lcm-logplayer --speed=1 --regexp="^RR_(GOAL|OBSTACLES)$" --lcm-url="$URL2" "$WORK/session.lcmlog"
logged_answer "$WORK/replay.lcmlog" "for goal 2: SUCCESS" "$URL2"
kill -INT "$LOGGER2"
wait "$LOGGER2" || true
"$KG" log-plans "$WORK/replay.lcmlog" --channel RR_PLAN --scene "$SCENE" --out-dir "$WORK/replayed" \
  | tee "$WORK/replayed.txt"
grep -Eq "for goal 1: (SUCCESS|SUPERSEDED)" "$WORK/replayed.txt" || fail "replayed goal 1 not answered"
grep -q "for goal 2: SUCCESS" "$WORK/replayed.txt" || fail "replayed goal 2 not planned"
echo "1 passed, 0 failed"
