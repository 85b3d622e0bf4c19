#!/usr/bin/env bash
# The simulated iiwa (`kinograph sim`) over real UDP multicast in a private network namespace,
# watched by lcm_probe (and, first, `kinograph send-state --utime`): before any command it holds the desk scene's start against gravity; a
# commanded posture with its gravity torque (the scene's goal, a step of up to 1.2 rad) is
# reached and then held within 1e-5 rad; ten times slower than the wall clock its states carry
# its own clock, 5 ms apart from the start time given, and kinographd stamps its plan on it.
# Usage: sim_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/integration/sim_lib.sh"
URL="udpm://239.255.76.67:7721?ttl=0&recv_buf_size=4194304"

# `kinograph send-state --utime` stamps the state on the robot's clock it is given.
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 1 --timeout 60 >"$WORK/sent.out" &
SENT_PROBE=$!
PIDS+=($SENT_PROBE)
wait_for_line "$WORK/sent.out" ready || fail "probe did not start"
"$KG" send-state --prefix IIWA --lcm-url "$URL" --scene "$SCENE" --q "$START" --utime 777
wait "$SENT_PROBE" || fail "the sent state did not arrive"
[ "$(value "$WORK/sent.out" first_utime)" -eq 777 ] || fail "send-state --utime not used"

start_sim "$URL"
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 200 --near "$START" >"$WORK/hold0.out" \
  || fail "no states from the simulator"
at_most "$(value "$WORK/hold0.out" max_deviation)" 1e-6 || fail "the start is not held: $(cat "$WORK/hold0.out")"

"$KG" send-command --prefix IIWA --lcm-url "$URL" --scene "$SCENE" --q "$GOAL" --gravity
"$PROBE" wait-near --url "$URL" --channel IIWA_STATE --near "$GOAL" --tol 1e-4 --count 200 \
  --timeout 120 || fail "the commanded posture was not reached"
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 400 --near "$GOAL" >"$WORK/hold1.out"
cat "$WORK/hold1.out"
at_most "$(value "$WORK/hold1.out" max_deviation)" 1e-5 || fail "the posture is not held within 1e-5 rad"
kill -INT "$SIM"
wait "$SIM" || fail "sim did not exit cleanly on SIGINT"
grep -q "1 commands, 0 refused" "$WORK/sim.log" || fail "the simulator did not count the command"

# Sim time: 10x slower than the wall clock, its clock starting at 5 s.
start_sim "$URL" --slowdown 10 --start-utime 5000000
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 40 >"$WORK/slow.out" || fail "no slow states"
cat "$WORK/slow.out"
first=$(value "$WORK/slow.out" first_utime)
last=$(value "$WORK/slow.out" last_utime)
wall=$(value "$WORK/slow.out" wall_us)
[ "$first" -ge 5000000 ] && [ "$first" -lt 1000000000 ] || fail "states are not on the sim clock"
[ "$(value "$WORK/slow.out" min_step_us)" -eq 5000 ] && [ "$(value "$WORK/slow.out" max_step_us)" -eq 5000 ] \
  || fail "states are not 5 ms apart on the sim clock"
# Ten times slower: 39 periods of 5 ms took 1.95 s of wall time; a fifth is the bound.
at_most $((5 * (last - first))) "$wall" || fail "the sim clock ran faster than a fifth of the wall clock"

start_kgd "$URL" --prefix IIWA
"$PROBE" states --url "$URL" --channel IIWA_STATE --count 1 >"$WORK/now.out"
now=$(value "$WORK/now.out" last_utime)
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime $((now + 100000)) \
  --wait 120 | tee "$WORK/plan.out" || fail "goal on the sim clock not planned"
grep -q "clock robot" "$WORK/plan.out" || fail "the plan is not on the robot's clock"
start=$(sed -n 's/.*starts at \([0-9]*\) us.*/\1/p' "$WORK/plan.out")
# Knot 0 is the latest state when planning began: at or after the state the probe saw, and on the
# sim clock (seconds after 5 s, not the epoch) however slowly the machine runs.
[ "$start" -ge "$now" ] && [ "$start" -le $((now + 10000000)) ] \
  || fail "plan starts at $start us, not on the sim's clock (at $now us)"
echo "1 passed, 0 failed"
