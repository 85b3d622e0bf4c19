# Sourced by the simulator's udpm tests: the daemon tests' private namespace, work directory and
# waiting (tests/daemon/udpm_lib.sh), plus the iiwa desk scene and the simulator, daemon and
# probe started and awaited on their own output. Exit 77 (skipped) when not root.
# The sourcing script sets BUILD and SRC and has been called with its own arguments in "$@".
source "$SRC/tests/daemon/udpm_lib.sh"

KG="$BUILD/tools/kinograph"
PROBE="$BUILD/tests/integration/lcm_probe"
SCENE="$SRC/robots/scenes/iiwa_desk.yaml"
# The desk scene's start and goal (robots/scenes/iiwa_desk.yaml).
START=0.801,1.333,-1.273,-1.753,0.067,-0.928,-0.188
GOAL=0.771,0.335,-0.570,-1.046,-0.686,0.356,-0.122
# udpm_lib.sh's fail() shows the daemon's log only; these tests have the simulator's too.
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.log; do echo "--- $f (tail)"; tail -n 20 "$f"; done
  exit 1
}

# Starts `kinograph sim` on the desk scene and URL $1 with the further options given, logging
# to $WORK/sim.log; sets SIM to its pid.
start_sim() {
  local url=$1
  shift
  "$KG" sim "$SCENE" --prefix IIWA --lcm-url "$url" "$@" >"$WORK/sim.log" 2>&1 &
  SIM=$!
  PIDS+=($SIM)
  wait_for_line "$WORK/sim.log" "kinograph sim: robot" || fail "sim did not start"
}

# Starts kinographd on the desk scene and URL $1 with the further options, logging to
# $WORK/daemon.log; sets DAEMON to its pid.
start_kgd() {
  local url=$1
  shift
  "$KGD" "$SCENE" --lcm-url "$url" --status-period 0.2 "$@" >"$WORK/daemon.log" 2>&1 &
  DAEMON=$!
  PIDS+=($DAEMON)
  wait_for_line "$WORK/daemon.log" "on channels" || fail "daemon did not start"
}

# Value of key $2 in the probe output file $1 ("key value" lines).
value() { awk -v k="$2" '$1 == k { print $2 }' "$1"; }

# True when the number $1 is at most $2.
at_most() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a <= b) }'; }
