#!/usr/bin/env bash
# What a scene file can say, said to a running kinographd with the CLI over real UDP multicast
# in a private network namespace: a goal with tolerances (goal_v3_t), a mesh obstacle by a path
# relative to the daemon's scene (mesh_obstacle_list_t), a payload attached and detached
# (payload_t). Each plan is checked by `kinograph validate` against a scene file that says the
# same, and refusals name what is wrong.
# Usage: cli_scene_messages_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"

KG="$BUILD/tools/kinograph"
KGD="$BUILD/daemon/kinographd"
URL="udpm://239.255.76.67:7704?ttl=0&recv_buf_size=4194304"
WORK=$(mktemp -d)
DAEMON=""
cleanup() {
  [ -z "$DAEMON" ] || kill "$DAEMON" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; echo "--- daemon log"; cat "$WORK"/daemon.log || true; exit 1; }
expect_in() { grep -qF -- "$1" "$2" || fail "'$1' not in $2: $(cat "$2")"; }

# The daemon's scene in WORK, so that the mesh's relative path resolves next to it.
SCENE="$WORK/scene.yaml"
sed "s|urdf: ../../robots/|urdf: $SRC/robots/|" "$SRC/tests/integration/rr_daemon.yaml" > "$SCENE"
# A 0.2 m cube at the top of the arm's swing.
printf 'v -0.1 -0.1 -0.1\nv 0.1 -0.1 -0.1\nv -0.1 0.1 -0.1\nv 0.1 0.1 -0.1\nv -0.1 -0.1 0.1\nv 0.1 -0.1 0.1\nv -0.1 0.1 0.1\nv 0.1 0.1 0.1\nf 1 2 4 3\nf 5 6 8 7\nf 1 2 6 5\nf 3 4 8 7\nf 1 3 7 5\nf 2 4 8 6\n' > "$WORK/block.obj"
WITH_BLOCK="$WORK/with_block.yaml"
{ cat "$SCENE"; printf 'obstacles:\n  - {id: block, shape: mesh, mesh: block.obj, position: [0, 0, 1.85]}\n'; } > "$WITH_BLOCK"
WITH_PAYLOAD="$WORK/with_payload.yaml"
sed 's|^  urdf: \(.*\)$|  urdf: \1\n  payload: {frame: ee, mass: 1.0, size: [0.1, 0.3, 0.1], offset: [0, 0.3, 0]}|' \
  "$SCENE" > "$WITH_PAYLOAD"

# Refusals before anything is sent (no daemon needed).
set +e
"$KG" send-goal --prefix RR --lcm-url "$URL" --q 0.8,-0.4 --joint-tolerance joint1=0.1 \
  >"$WORK/out.txt" 2>&1
code=$?
set -e
[ "$code" -eq 1 ] || fail "send-goal --q with a tolerance exited $code"
expect_in "--q sends goal_t, which has no tolerances" "$WORK/out.txt"
set +e
"$KG" send-obstacle --prefix RR --lcm-url "$URL" --id x --shape mesh >"$WORK/out.txt" 2>&1
code=$?
set -e
[ "$code" -eq 1 ] || fail "send-obstacle --shape mesh without --mesh exited $code"
expect_in "--shape mesh needs --mesh" "$WORK/out.txt"

"$KGD" "$SCENE" --prefix RR --lcm-url "$URL" >"$WORK/daemon.log" 2>&1 &
DAEMON=$!
for _ in $(seq 100); do grep -q "on channels RR_" "$WORK/daemon.log" && break; sleep 0.1; done
grep -q "on channels RR_" "$WORK/daemon.log" || fail "daemon did not start"

# A goal with tolerances 100 times tighter than the default: a goal_v3_t, met.
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 1 --joint joint1=0.8 --joint joint2=-0.4 \
  --joint-tolerance joint1=1e-4 --joint-tolerance joint2=1e-4 --wait 60 --scene "$SCENE" \
  --out "$WORK/plan1.json" >"$WORK/out.txt" 2>&1 || fail "goal 1: $(cat "$WORK/out.txt")"
expect_in "(goal_v3_t)" "$WORK/out.txt"
goal_error=$(sed -n 's/.*goal error \([^,]*\),.*/\1/p' "$WORK/out.txt")
awk -v e="$goal_error" 'BEGIN { exit !(e <= 1e-4) }' || fail "goal error $goal_error > 1e-4"
# Its straight swing goes through where the block will be.
set +e
"$KG" validate "$WITH_BLOCK" "$WORK/plan1.json" >"$WORK/out.txt" 2>&1
code=$?
set -e
[ "$code" -eq 2 ] || fail "plan 1 validates against the block: $(cat "$WORK/out.txt")"

# The block by a path relative to the daemon's scene: the replan goes around it.
"$KG" send-obstacle --prefix RR --lcm-url "$URL" --id block --shape mesh --mesh block.obj \
  --position 0,0,1.85 --goal-id 1 --wait 60 --scene "$SCENE" --out "$WORK/replan.json" \
  >"$WORK/out.txt" 2>&1 || fail "mesh replan: $(cat "$WORK/out.txt")"
expect_in "(mesh_obstacle_list_t)" "$WORK/out.txt"
"$KG" validate "$WITH_BLOCK" "$WORK/replan.json" >"$WORK/out.txt" 2>&1 \
  || fail "the replan does not clear the block: $(cat "$WORK/out.txt")"
"$KG" send-obstacle --prefix RR --lcm-url "$URL" --id block --shape mesh --remove >/dev/null

# A missing mesh is refused, naming the file.
"$KG" send-obstacle --prefix RR --lcm-url "$URL" --id gone --shape mesh --mesh gone.obj \
  --position 0,0,2 >/dev/null
for _ in $(seq 100); do grep -q "gone.obj' not found" "$WORK/daemon.log" && break; sleep 0.1; done
expect_in "mesh_obstacle_list_t.obstacles[0] (\"gone\").mesh: file 'gone.obj' not found" "$WORK/daemon.log"

# A payload attached: the next plan is the loaded arm's (dynamics and clearance), not the bare one's.
"$KG" send-payload --prefix RR --lcm-url "$URL" --frame ee --mass 1 --size 0.1,0.3,0.1 \
  --offset 0,0.3,0 >/dev/null
for _ in $(seq 100); do grep -q "payload of 1.000000 kg attached to 'ee'" "$WORK/daemon.log" && break; sleep 0.1; done
expect_in "payload of 1.000000 kg attached to 'ee'" "$WORK/daemon.log"
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 2 --joint joint1=0.8 --joint joint2=-0.4 \
  --wait 60 --scene "$WITH_PAYLOAD" --out "$WORK/plan2.json" >"$WORK/out.txt" 2>&1 \
  || fail "goal 2 with the payload: $(cat "$WORK/out.txt")"
"$KG" validate "$WITH_PAYLOAD" "$WORK/plan2.json" >"$WORK/out.txt" 2>&1 \
  || fail "plan 2 does not validate with the payload: $(cat "$WORK/out.txt")"
set +e
"$KG" validate "$SCENE" "$WORK/plan2.json" >"$WORK/out.txt" 2>&1
code=$?
set -e
[ "$code" -eq 2 ] || fail "plan 2 validates for the bare arm (exit $code): no payload planned for"

# Detached: the next plan is the bare arm's again; a payload on an unknown frame is refused.
"$KG" send-payload --prefix RR --lcm-url "$URL" --detach >/dev/null
for _ in $(seq 100); do grep -q "payload detached" "$WORK/daemon.log" && break; sleep 0.1; done
"$KG" send-goal --prefix RR --lcm-url "$URL" --id 3 --joint joint1=0.8 --joint joint2=-0.4 \
  --wait 60 --scene "$SCENE" --out "$WORK/plan3.json" >"$WORK/out.txt" 2>&1 \
  || fail "goal 3 after the detach: $(cat "$WORK/out.txt")"
"$KG" validate "$SCENE" "$WORK/plan3.json" >/dev/null || fail "plan 3 is not the bare arm's"
"$KG" send-payload --prefix RR --lcm-url "$URL" --frame nowhere --mass 1 --size 0.1,0.1,0.1 \
  >/dev/null
for _ in $(seq 100); do grep -q 'payload_t.frame "nowhere"' "$WORK/daemon.log" && break; sleep 0.1; done
expect_in 'payload_t.frame "nowhere" is not a frame of rr' "$WORK/daemon.log"

kill -TERM "$DAEMON"
wait "$DAEMON" || fail "daemon did not exit cleanly on SIGTERM"
DAEMON=""
echo "1 passed, 0 failed"
