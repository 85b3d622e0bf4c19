# Shared by the daemon's udpm tests (sourced): a private network namespace with a loopback
# multicast route (nothing leaves it), a work directory, and daemons started and awaited on
# their own log line. Exit 77 (skipped) when not root.
# The sourcing script sets BUILD and SRC and has been called with its own arguments in "$@".
source "$SRC/tests/lib/private_netns.sh"

KGD="$BUILD/daemon/kinographd"
STORM="$BUILD/tests/daemon/goal_storm"
WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill -CONT "$p" 2>/dev/null || true; kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; echo "--- daemon log (tail)"; tail -n 40 "$WORK"/daemon*.log || true; exit 1; }

# Waits (bounded, 30 s) until file $1 contains the text $2.
wait_for_line() {
  for _ in $(seq 300); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done
  return 1
}

# Starts kinographd on scene $1, URL $2, logging to $3, and waits until it is subscribed.
# Sets DAEMON to its pid.
start_daemon() {
  "$KGD" "$1" --prefix RR --lcm-url "$2" --status-period 0.2 >"$3" 2>&1 &
  DAEMON=$!
  PIDS+=($DAEMON)
  wait_for_line "$3" "on channels RR_" || fail "daemon did not start"
}
