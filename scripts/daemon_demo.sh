#!/usr/bin/env bash
# The daemon demo, end to end over real LCM: kinographd serves the iiwa of robots/scenes/
# iiwa_desk.yaml; the CLI sends it a goal (planned from scratch), then drops a ball into the
# workspace (the daemon replans goal 1 incrementally, iDFGP), then sends a second goal near the
# first (an incremental replan too); lcm-logger records the session. Each answer prints its
# method ("batch", "incremental", "batch after incremental") and solve time. Plans and pictures
# go to out/daemon/.
# As root it runs in a private network namespace whose loopback carries the multicast group,
# so no packet leaves this machine; otherwise it uses the in-process-free default URL with
# ttl=0 (packets stay on this host).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/demo_netns.sh
URL="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"
BUILD=${KINOGRAPH_BUILD_DIR:-build}
KG="$BUILD/tools/kinograph"
SCENE=robots/scenes/iiwa_desk.yaml
OUT=out/daemon
mkdir -p "$OUT"
PIDS=()
trap 'for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true' EXIT

lcm-logger -f --lcm-url="$URL" "$OUT/session.lcmlog" >"$OUT/lcm-logger.log" 2>&1 &
LOGGER=$!
PIDS+=($LOGGER)
"$BUILD/daemon/kinographd" "$SCENE" --prefix IIWA --lcm-url "$URL" >"$OUT/kinographd.log" 2>&1 &
DAEMON=$!
PIDS+=($DAEMON)
for _ in $(seq 100); do grep -q "on channels" "$OUT/kinographd.log" && break; sleep 0.1; done

echo "== goal 1: carry the block from under the desk to above it"
rc=0
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 1 \
  --q 0.771,0.335,-0.570,-1.046,-0.686,0.356,-0.122 --wait 120 \
  --scene "$SCENE" --out "$OUT/goal1.json" || rc=$?
echo "== a ball appears beside the desk on the block's way up: the daemon replans goal 1"
"$KG" send-obstacle --prefix IIWA --lcm-url "$URL" --id ball --shape sphere --size 0.05 \
  --position 0.5,0.6,0.7 --goal-id 1 --wait 120 --scene "$SCENE" \
  --out "$OUT/goal1_replan.json" || rc=$?
echo "== goal 2, near goal 1 (the base turned 0.15 rad): replanned incrementally around the ball"
"$KG" send-goal --prefix IIWA --lcm-url "$URL" --id 2 \
  --q 0.921,0.335,-0.570,-1.046,-0.686,0.356,-0.122 --wait 120 \
  --scene "$SCENE" --out "$OUT/goal2.json" || rc=$?

kill -TERM "$DAEMON"
wait "$DAEMON" || true
kill -INT "$LOGGER"
wait "$LOGGER" || true
echo "== the daemon's log: one line per plan (method, time) and the iDFGP statistics"
grep -E "goal [0-9]+: plan|iDFGP:|fell back|stopped after" "$OUT/kinographd.log" | cut -c 27-
"$KG" log-plans "$OUT/session.lcmlog" --channel IIWA_PLAN --scene "$SCENE" --out-dir "$OUT/plans" \
  >/dev/null
for plan in goal1 goal1_replan goal2; do
  if [ -f "$OUT/$plan.json" ]; then
    "$KG" render "$OUT/$plan.json" --scene "$SCENE" --frames 5 --out "$OUT/${plan}_strip.png"
  fi
done
exit $rc
