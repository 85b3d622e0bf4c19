# Sourced by the closed-loop udpm tests: sim_lib.sh plus the loop itself — lcm-logger recording
# the given channels, `kinograph sim`, kinographd and `kinograph execute` on $URL — the robot's
# latest time, and stopping them all once the arm rests at a goal. The sourcing script sets
# BUILD, SRC and URL.
source "$SRC/tests/integration/sim_lib.sh"
# With the simulator 10x slower than the wall clock, 0.5 s of its clock is 5 s of the wall's:
# more than a batch replan takes on a loaded machine, so take-over times are met.
LATENCY=0.5

# start_loop LOG CHANNELS SIM_OPTIONS...: the logger (channels regex) into LOG, the simulator
# with the options given, the daemon (--takeover-latency $LATENCY, robot seconds) and the
# executor; each awaited on its own output.
start_loop() {
  local log=$1 channels=$2
  shift 2
  lcm-logger -f -c "$channels" --lcm-url="$URL" "$log" >"$WORK/logger.log" 2>&1 &
  LOGGER=$!
  PIDS+=($LOGGER)
  start_sim "$URL" "$@"
  for _ in $(seq 300); do [ -s "$log" ] && break; sleep 0.1; done
  [ -s "$log" ] || fail "lcm-logger records nothing"
  start_kgd "$URL" --prefix IIWA --takeover-latency "$LATENCY"
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

# arrive_and_stop Q: waits until 200 consecutive states are within 1e-2 rad of Q, then stops
# the processes (the executor and the simulator print their summaries on the way out).
arrive_and_stop() {
  "$PROBE" wait-near --url "$URL" --channel IIWA_STATE --near "$1" --tol 1e-2 --count 200 \
    --timeout 300 || fail "the arm did not arrive within 1e-2 rad of $1"
  for p in $EXECUTOR $SIM $DAEMON $LOGGER; do kill -INT "$p"; done
  wait "$EXECUTOR" || fail "executor did not exit cleanly"
  wait "$SIM" || fail "sim did not exit cleanly"
  wait "$DAEMON" || true
  wait "$LOGGER" || true
  PIDS=()
}

# check_takeovers: at least $1 take-overs from a plan in the executor's summary, none jumping
# more than 1e-6 rad or 1e-4 rad/s.
check_takeovers() {
  local summary switches jq jqd
  summary=$(grep "kinograph execute:" "$WORK/execute.log")
  echo "$summary"
  switches=$(echo "$summary" | sed -n 's/.*; \([0-9]*\) take-overs from a plan.*/\1/p')
  jq=$(echo "$summary" | sed -n 's/.*largest jump \([^ ]*\) rad, .*/\1/p')
  jqd=$(echo "$summary" | sed -n 's/.*rad, \([^ ]*\) rad\/s.*/\1/p')
  [ "$switches" -ge "$1" ] || fail "$switches take-overs, expected at least $1"
  at_most "$jq" 1e-6 || fail "a take-over jumps $jq rad"
  at_most "$jqd" 1e-4 || fail "a take-over jumps $jqd rad/s"
  if grep -q "after its take-over" "$WORK/daemon.log"; then
    fail "a replan came after its take-over time"
  fi
}

# Goal i of a goal moving slowly: the desk goal with the base joint turned 0.004·i rad.
goal_q() { echo "$GOAL" | awk -F, -v i="$1" '{ $1 = $1 + 0.004 * i; print }' OFS=,; }

# stream_goals N: goal 1 (goal_q 1) from rest, and once the executor follows its plan (so the
# daemon has heard it), goals 2..N, one every 0.1 s of the robot's clock, each stamped with the
# latest state's time. Waits on the robot's clock (its states), never on a fixed sleep.
stream_goals() {
  local next now
  next=$(robot_now)
  "$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$(goal_q 1)" --utime "$next" \
    --wait 120 >/dev/null || fail "goal 1 not answered with a valid plan"
  wait_for_line "$WORK/execute.log" "plan 1 takes over" || fail "the executor did not follow plan 1"
  next=$((next + 100000))
  for i in $(seq 2 "$1"); do
    while now=$(robot_now) && [ "$now" -lt "$next" ]; do :; done
    "$KG" send-goal --prefix IIWA --lcm-url "$URL" --id "$i" --q "$(goal_q "$i")" --utime "$now" \
      >/dev/null
    next=$((next + 100000))
  done
}
