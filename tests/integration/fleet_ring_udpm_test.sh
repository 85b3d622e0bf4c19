#!/usr/bin/env bash
# Four iiwa arms in a ring around a table, each sweeping its hand across the others' paths (planned
# alone, two of them overlap by 0.11 m), one kinographd each with the other three as neighbours,
# over real UDP multicast in a private network namespace. The goals go out one after another;
# once the fleet has settled under the coordination rule every plan validates and all four,
# checked together at and between the knots, keep clear.
# Usage: fleet_ring_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7712?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

ARMS=(west south east north)
robots=() plans=()
for arm in "${ARMS[@]}"; do
  neighbours=()
  for other in "${ARMS[@]}"; do
    [ "$other" = "$arm" ] || neighbours+=(--neighbour "$other=$SCENES/iiwa_ring_$other.yaml")
  done
  start_robot "$arm" "$SCENES/iiwa_ring_$arm.yaml" "${neighbours[@]}"
  robots+=(--robot "$(echo "$arm" | tr '[:lower:]' '[:upper:]')=$SCENES/iiwa_ring_$arm.yaml")
  plans+=("$arm=$SCENES/iiwa_ring_$arm.yaml")
done
watch "${robots[@]}"
for arm in "${ARMS[@]}"; do send_goal "$arm" 1 "-0.8,0.7,0,-1.3,0,0.8,0" "$SCENES/iiwa_ring_$arm.yaml"; done
await_settled
check_plans "${plans[@]}"
echo "1 passed, 0 failed"
