#!/usr/bin/env bash
# Two robots on two "hosts": left's kinographd in this private network namespace, right's in a
# second one, joined by a veth pair, LCM over UDP multicast with ttl=1 (one hop, nothing leaves
# the pair). Crossing goals as in fleet_pair_udpm_test.sh: both plans validate and, checked
# together, keep clear.
# Usage: fleet_hosts_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7713?ttl=1&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"
LEFT="$SCENES/iiwa_pair_left.yaml"
RIGHT="$SCENES/iiwa_pair_right.yaml"

# Host B: a child network namespace that waits for its end of the pair, configures it and runs
# right's daemon.
cat >"$WORK/host_b.sh" <<HOST
set -e
for _ in \$(seq 600); do ip link show veth_b >/dev/null 2>&1 && break; sleep 0.05; done
ip link set lo up
ip addr add 10.77.0.2/24 dev veth_b
ip link set veth_b up
ip route add 224.0.0.0/4 dev veth_b
exec "$KGD" "$RIGHT" --prefix RIGHT --lcm-url "$URL" --status-period 0.2 --neighbour "left=$LEFT"
HOST
unshare -n bash "$WORK/host_b.sh" >"$WORK/right.log" 2>&1 &
PID[right]=$!
# Host A (here): the other end, and multicast through it instead of the loopback. The pair's
# far end goes to host B only once its process has its own namespace (before that it would
# land here, and host B would wait for it in vain).
own_ns=$(readlink /proc/self/ns/net)
for _ in $(seq 600); do
  ns=$(readlink "/proc/${PID[right]}/ns/net" 2>/dev/null) || fail "host B ended before it began"
  [ "$ns" != "$own_ns" ] && break
  sleep 0.05
done
[ "$ns" != "$own_ns" ] || fail "host B has no network namespace of its own after 30 s"
ip link add veth_a type veth peer name veth_b
ip link set veth_b netns "${PID[right]}"
ip addr add 10.77.0.1/24 dev veth_a
ip link set veth_a up
ip route del 224.0.0.0/4 dev lo
ip route add 224.0.0.0/4 dev veth_a
wait_for_line "$WORK/right.log" "on channels RIGHT_" || fail "right did not start on host B"
start_robot left "$LEFT" --neighbour "right=$RIGHT"

watch --robot "LEFT=$LEFT" --robot "RIGHT=$RIGHT"
send_goal left 1 "-0.6,0.7,0,-1.3,0,0.8,0" "$LEFT"
send_goal right 1 "-0.6,0.7,0,-1.3,0,0.8,0" "$RIGHT"
await_settled
check_plans "left=$LEFT" "right=$RIGHT"
grep -q "^RIGHT: .*neighbours: left: plan [0-9]*, followed" "$WORK/probe.out" \
  || fail "right on host B does not follow left's plan from host A"
echo "1 passed, 0 failed"
