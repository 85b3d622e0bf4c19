#!/usr/bin/env bash
# kinographd plans in the batch formulation of --formulation, else of the scene's
# planner.formulation, over real UDP multicast inside a private network namespace (nothing
# leaves this machine's loopback). The plan tells: condensed torques are RNEA of the trajectory
# (dynamics residual 0), the full DFG's are its own τ variables (a residual at the solver's
# tolerance). --batch-only, so that the answer is the batch solve itself.
# Usage: daemon_formulation_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"

KG="$BUILD/tools/kinograph"
KGD="$BUILD/daemon/kinographd"
URL="udpm://239.255.76.67:7703?ttl=0&recv_buf_size=4194304"
WORK=$(mktemp -d)
DAEMON=""
cleanup() {
  [ -z "$DAEMON" ] || kill "$DAEMON" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
fail() { echo "FAIL: $*"; echo "--- daemon log"; cat "$WORK"/daemon.log || true; exit 1; }

# The integration scene with planner.formulation: dfg (the URDF path made absolute).
CONDENSED="$SRC/tests/integration/rr_daemon.yaml"
DFG="$WORK/rr_daemon_dfg.yaml"
sed "s|urdf: ../../robots/|urdf: $SRC/robots/|" "$CONDENSED" > "$DFG"
printf 'planner:\n  formulation: dfg\n' >> "$DFG"

# Serves scene $1 with extra flags $2, sends one goal and checks that the daemon names
# formulation $3 and that the plan's dynamics residual is zero (condensed) or not (dfg).
check() {
  local scene=$1 flags=$2 expected=$3
  # shellcheck disable=SC2086
  "$KGD" "$scene" --prefix RR --lcm-url "$URL" --batch-only $flags >"$WORK/daemon.log" 2>&1 &
  DAEMON=$!
  for _ in $(seq 100); do grep -q "on channels RR_" "$WORK/daemon.log" && break; sleep 0.1; done
  grep -q "on channels RR_" "$WORK/daemon.log" || fail "daemon did not start ($flags)"
  grep -q "batch formulation $expected" "$WORK/daemon.log" \
    || fail "daemon does not plan in the $expected formulation ($scene $flags)"
  "$KG" send-goal --prefix RR --lcm-url "$URL" --id 1 --q 0.8,-0.4 --wait 60 \
    --scene "$CONDENSED" --out "$WORK/plan.json" >/dev/null || fail "goal not answered ($flags)"
  local residual
  residual=$(sed -n 's/.*"max_dynamics_residual": \([^,]*\),*/\1/p' "$WORK/plan.json")
  [ -n "$residual" ] || fail "plan JSON has no max_dynamics_residual"
  case $expected in
    condensed) awk -v r="$residual" 'BEGIN { exit !(r < 1e-9) }' \
                 || fail "condensed plan has a dynamics residual $residual" ;;
    dfg) awk -v r="$residual" 'BEGIN { exit !(r > 1e-9) }' \
           || fail "dfg plan has no dynamics residual ($residual): not the DFG's own torques" ;;
  esac
  kill -TERM "$DAEMON"
  wait "$DAEMON" || fail "daemon did not exit cleanly on SIGTERM"
  DAEMON=""
}

check "$CONDENSED" "" condensed
check "$CONDENSED" "--formulation dfg" dfg
check "$DFG" "" dfg
check "$DFG" "--formulation condensed" condensed
echo "1 passed, 0 failed"
