#!/usr/bin/env bash
# Four iiwa arms in a ring around a round table with crossing goals (robots/scenes/iiwa_ring_*.yaml:
# the four straight joint-space motions together collide, every goal is clear of the other arms'
# starts and goals), one kinographd each with the other three as neighbours, over real UDP
# multicast in a private network namespace. The goals go out in the order of their priority
# (goal time), each awaited; once the fleet has settled under the coordination rule every plan
# validates and all four, checked together at and between the knots, keep clear.
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

# Each arm's goal is its scene's; the goal times are one second apart, so a outranks b, c, d.
watch "${robots[@]}"
T0=$(date +%s%6N)
for k in "${!ARMS[@]}"; do
  arm=${ARMS[$k]}
  scene="$SCENES/iiwa_ring_$arm.yaml"
  goal=$(sed -n '/^goal:/,/^[a-z]/ s/^  q: \[\(.*\)\]/\1/p' "$scene" | tr -d ' ')
  send_goal "$arm" 1 "$goal" "$scene" $((T0 + k * 1000000))
done
await_settled
check_plans "${plans[@]}"
for arm in b c d; do
  grep -q "^${arm^^}: .*neighbours: a: plan [0-9]*, followed" "$WORK/probe.out" \
    || fail "$arm does not follow a's plan"
done
echo "PASS: four arms in a ring"
echo "1 passed, 0 failed"
