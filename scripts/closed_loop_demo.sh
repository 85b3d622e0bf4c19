#!/usr/bin/env bash
# The loop closed, end to end over real LCM: kinographd plans for the simulated iiwa of
# robots/scenes/iiwa_desk.yaml (`kinograph sim`, 4x slower than the wall clock), `kinograph
# execute` streams the plans to it as setpoints. A goal; while the arm moves, a ball appears in
# its way (robots/scenes/changes/iiwa_desk_late_ball.yaml); the daemon replans from where the
# commanded motion will be at the take-over, the executor switches there, the arm arrives.
# lcm-logger records the states and plans; the demo prints the take-overs, the tracking error
# and the executed path's clearance, and draws the executed path beside the first plan
# (out/closed_loop/). As root it runs in a private network namespace (as daemon_demo.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/demo_netns.sh
URL="udpm://239.255.76.67:7668?ttl=0&recv_buf_size=4194304"
BUILD=${KINOGRAPH_BUILD_DIR:-build}
KG="$BUILD/tools/kinograph"
SCENE=robots/scenes/iiwa_desk.yaml
BALL=robots/scenes/changes/iiwa_desk_late_ball.yaml
GOAL=0.771,0.335,-0.570,-1.046,-0.686,0.356,-0.122
OUT=out/closed_loop
rm -rf "$OUT"
mkdir -p "$OUT"
PIDS=()
trap 'for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true' EXIT
# Waits (bounded, 60 s) until file $1 contains the text $2.
wait_for() {
  for _ in $(seq 600); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done
  echo "no \"$2\" in $1"; exit 1
}
# Value of key $2 in `kinograph check-states` output $1.
value() { awk -v k="$2" '$1 == k { print $2 }' "$1"; }

lcm-logger -f -c 'IIWA_STATE|IIWA_PLAN' --lcm-url="$URL" "$OUT/session.lcmlog" \
  >"$OUT/lcm-logger.log" 2>&1 &
PIDS+=($!)
"$KG" sim "$SCENE" --prefix IIWA --lcm-url "$URL" --slowdown 4 --start-utime 1000000 \
  >"$OUT/sim.log" 2>&1 &
SIM=$!
PIDS+=($SIM)
wait_for "$OUT/sim.log" "kinograph sim: robot"
"$BUILD/daemon/kinographd" "$SCENE" --prefix IIWA --lcm-url "$URL" --takeover-latency 0.5 \
  >"$OUT/kinographd.log" 2>&1 &
DAEMON=$!
PIDS+=($DAEMON)
wait_for "$OUT/kinographd.log" "on channels"
"$KG" execute "$SCENE" --prefix IIWA --lcm-url "$URL" >"$OUT/execute.log" 2>&1 &
EXECUTOR=$!
PIDS+=($EXECUTOR)
wait_for "$OUT/execute.log" "kinograph execute: robot"
# The robot's clock: the latest recorded state.
now() { "$KG" check-states "$OUT/session.lcmlog" --scene "$SCENE" | awk '$1 == "last_utime" { print $2 }'; }
for _ in $(seq 100); do [ -s "$OUT/session.lcmlog" ] && break; sleep 0.1; done

echo "== goal 1: carry the block from under the desk to above it (the arm starts moving)"
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 --q "$GOAL" --utime "$(now)" --wait 120 \
  | head -n 1
wait_for "$OUT/execute.log" "plan 1 takes over"
echo "== a ball appears in the arm's way: the daemon replans from where the motion will be"
"$KG" send-obstacle --prefix IIWA --lcm-url "$URL" --id ball --shape sphere --size 0.05 \
  --position 0.25,0.5,0.6 --utime "$(now)" --goal-id 1 --wait 120 | sed -n '2p;5p'
echo "== the arm arrives"
for _ in $(seq 240); do
  "$KG" check-states "$OUT/session.lcmlog" --scene "$SCENE" --change "$BALL" >"$OUT/states.out"
  awk -v e="$(value "$OUT/states.out" final_goal_error)" -v v="$(value "$OUT/states.out" final_speed)" \
    'BEGIN { exit !(e <= 1e-2 && v <= 1e-3) }' && break
  sleep 0.5
done
for p in $EXECUTOR $SIM $DAEMON "${PIDS[0]}"; do kill -INT "$p" 2>/dev/null || true; done
wait 2>/dev/null || true
PIDS=()
grep "takes over" "$OUT/execute.log" | cut -c 27-
grep "kinograph execute:" "$OUT/execute.log"
grep "kinograph sim: tracking" "$OUT/sim.log"
"$KG" check-states "$OUT/session.lcmlog" --scene "$SCENE" --change "$BALL" \
  --out "$OUT/executed.json" >"$OUT/states.out"
echo "executed path: clearance to the desk, the ball, the floor and itself at least" \
  "$(value "$OUT/states.out" min_clearance) m ($(grep closest_pair "$OUT/states.out" | cut -d' ' -f2-));" \
  "final error to the goal $(value "$OUT/states.out" final_goal_error) rad"
"$KG" log-plans "$OUT/session.lcmlog" --channel IIWA_PLAN --scene "$SCENE" --out-dir "$OUT/plans" \
  >/dev/null
if "$KG" render --help >/dev/null 2>&1; then
  "$KG" render "$OUT/plans/plan_1_1.json" --compare "$OUT/executed.json" --scene "$SCENE" \
    --frames 5 --width 1000 --height 800 --before-label "planned before the ball: grey robot, green path" \
    --after-label "executed, replanned around the ball: robot colours, red path" \
    --out "$OUT/executed_vs_planned.png"
fi
