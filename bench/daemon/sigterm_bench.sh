#!/usr/bin/env bash
# SIGTERM during a plan, measured: sigterm_bench on the iiwa desk task at 400 steps (a plan of
# seconds), in a private network namespace, beside BUSY busy-loop processes (default 2, as
# many as the development machine's cores) that are started here and killed by their PIDs.
# Usage: sigterm_bench.sh BUILD_DIR [TRIALS] [BUSY] [--json FILE ...sigterm_bench flags]
# Needs root (unshare -n). Exit status: sigterm_bench's (3 when an exit took over 100 ms).
set -euo pipefail
BUILD=$(realpath "$1")
SRC=$(cd "$(dirname "$0")/../.." && pwd)
TRIALS=${2:-20}
BUSY=${3:-2}
EXTRA=("${@:4}")
if [ -z "${KINOGRAPH_NETNS:-}" ]; then
  [ "$(id -u)" -eq 0 ] || { echo "sigterm_bench.sh: needs root (unshare -n)"; exit 77; }
  exec unshare -n env KINOGRAPH_NETNS=1 bash "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo

WORK=$(mktemp -d)
BUSY_PIDS=()
cleanup() {
  for p in "${BUSY_PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT
sed "s/^steps: 30$/steps: 400/; s|\.\./iiwa14/|$SRC/robots/iiwa14/|" \
  "$SRC/robots/scenes/iiwa_desk.yaml" >"$WORK/iiwa_desk_slow.yaml"
for _ in $(seq "$BUSY"); do
  sh -c 'while :; do :; done' &
  BUSY_PIDS+=($!)
done
echo "busy loops: ${BUSY_PIDS[*]:-none}; $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)" >&2
nice -n -10 "$BUILD/bench/daemon/sigterm_bench" --daemon "$BUILD/daemon/kinographd" \
  --scene "$WORK/iiwa_desk_slow.yaml" --url "udpm://239.255.76.67:7719?ttl=0" \
  --trials "$TRIALS" --logs "$WORK" "${EXTRA[@]}"
