#!/usr/bin/env bash
# Four iiwa arms in a ring around a round table with crossing goals (robots/scenes/iiwa_ring_*.yaml:
# the four straight joint-space motions together collide, every goal is clear of the other arms'
# starts and goals), one kinographd each with the other three as neighbours, over real UDP
# multicast in a private network namespace. All four get measured states at their starts on one
# robot clock, so every plan starts there at the same time. The goals go out in the order of
# their priority (goal time), each awaited; once the fleet has settled under the coordination
# rule every plan validates and all four, checked together at and between the knots, keep clear.
# Then the first arm's goal moves, keeping its priority, and the fleet settles again, clear.
# Usage: fleet_ring_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7712?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

ARMS=(a b c d)
robots=() plans=()
for arm in "${ARMS[@]}"; do
  neighbours=()
  for other in "${ARMS[@]}"; do
    [ "$other" = "$arm" ] || neighbours+=(--neighbour "$other=$SCENES/iiwa_ring_$other.yaml")
  done
  start_robot "$arm" "$SCENES/iiwa_ring_$arm.yaml" "${neighbours[@]}"
  robots+=(--robot "${arm^^}=$SCENES/iiwa_ring_$arm.yaml")
  plans+=("$arm=$SCENES/iiwa_ring_$arm.yaml")
done

# scene_q SCENE KEY: the scene's start or goal q, comma-separated.
scene_q() { sed -n "/^$2:/,/^[a-z]/ s/^  q: \[\(.*\)\]/\1/p" "$1" | tr -d ' '; }
# send_states UTIME: every arm at its scene's start at UTIME on the robots' common clock.
send_states() {
  for arm in "${ARMS[@]}"; do
    "$KG" send-state --prefix "${arm^^}" --lcm-url "$URL" --scene "$SCENES/iiwa_ring_$arm.yaml" \
      --q "$(scene_q "$SCENES/iiwa_ring_$arm.yaml" start)" --utime "$1" >/dev/null
  done
}

# 1. Each arm's goal is its scene's, a's first: a outranks b, c, d, b outranks c, d, ...
T=1000000000000
send_states $T
watch "${robots[@]}"
for k in "${!ARMS[@]}"; do
  arm=${ARMS[$k]}
  scene="$SCENES/iiwa_ring_$arm.yaml"
  send_goal "$arm" 1 "$(scene_q "$scene" goal)" "$scene" $((T + 100 * (k + 1)))
done
await_settled
check_plans "${plans[@]}"
for arm in b c d; do
  grep -q "^${arm^^}: .*neighbours: a: plan [0-9]*, followed" "$WORK/probe.out" \
    || fail "$arm does not follow a's plan"
done
echo "PASS: four arms in a ring"

# 2. a's goal moves (its first joint by 0.15 rad, still clear of the others' starts and goals),
# keeping its priority: b, c and d replan around a's new plan, each also around the replans above
# it.
A2="-2.583,-0.9678,-1.7097,1.4194,-1.1171,1.5201,-2.6013"
newer=()
for arm in "${ARMS[@]}"; do newer+=(--newer "${arm^^}=$(current_plan "${arm^^}")"); done
T=$((T + 10000000))
send_states $T
watch "${robots[@]}" "${newer[@]}"
send_goal a 2 "$A2" "$SCENES/iiwa_ring_a.yaml" $((1000000000000 + 100))
await_settled
check_plans "a=$(with_goal "$SCENES/iiwa_ring_a.yaml" "$A2" a2)" "${plans[@]:1}"
for arm in b c d; do
  grep -q "^${arm^^}: .* [1-9][0-9]* neighbour replans" "$WORK/probe.out" \
    || fail "$arm did not replan around a's new plan"
done
echo "PASS: the first arm's goal moved, the others replanned"
echo "2 passed, 0 failed"
