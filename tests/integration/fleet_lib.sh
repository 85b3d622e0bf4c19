# Shared by the multi-robot udpm tests (sourced after private_netns.sh): daemons with
# --neighbour started and awaited on their own log line, goals sent, the fleet awaited with
# fleet_probe and its plans checked together and one by one.
# The sourcing script sets BUILD, SRC and URL.
KG="$BUILD/tools/kinograph"
KGD="$BUILD/daemon/kinographd"
PROBE="$BUILD/tests/integration/fleet_probe"
SCENES="$SRC/robots/scenes"
WORK=$(mktemp -d)
declare -A PID
cleanup() {
  for p in "${PID[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*"
  for f in "$WORK"/*.log; do echo "--- $f (tail)"; tail -n 25 "$f"; done
  exit 1
}

# Waits (bounded, 60 s) until file $1 contains the text $2, after its first $3 lines (default
# 0: anywhere).
wait_for_line() {
  for _ in $(seq 600); do
    tail -n "+$((${3:-0} + 1))" "$1" 2>/dev/null | grep -q -- "$2" && return 0
    sleep 0.1
  done
  return 1
}

# start_robot NAME SCENE [--neighbour ...]: kinographd for robot NAME (prefix NAME upper-cased)
# logging to $WORK/NAME.log, awaited until subscribed. A restarted robot appends to its log: only
# the new daemon's lines count, or a message sent at once could reach no one.
start_robot() {
  local name=$1 scene=$2 prefix before=0
  prefix=$(echo "$1" | tr '[:lower:]' '[:upper:]')
  [ ! -f "$WORK/$name.log" ] || before=$(wc -l <"$WORK/$name.log")
  "$KGD" "$scene" --prefix "$prefix" --lcm-url "$URL" --status-period 0.2 "${@:3}" \
    >>"$WORK/$name.log" 2>&1 &
  PID[$name]=$!
  wait_for_line "$WORK/$name.log" "on channels ${prefix}_" "$before" || fail "$name did not start"
}

# send_goal NAME ID Q SCENE [UTIME]: a joint goal, awaited (its first answer must be a valid
# plan); UTIME stamps it (its priority, docs/multi_robot.md), default now.
send_goal() {
  local prefix utime=${5:-$(date +%s%6N)}
  prefix=$(echo "$1" | tr '[:lower:]' '[:upper:]')
  "$KG" send-goal --prefix "$prefix" --lcm-url "$URL" --id "$2" --q "$3" --wait 120 \
    --utime "$utime" \
    --scene "$4" --out "$WORK/$1_first.json" >"$WORK/$1_goal_$2.out" 2>&1 \
    || fail "goal $2 of $1 not answered with a valid plan: $(tail -3 "$WORK/$1_goal_$2.out")"
}

# watch ARGS...: starts fleet_probe settle with the given --robot/--newer arguments, before the
# goals are sent so that it hears every plan; await_settled waits for it. The robots' current
# plans land in $WORK/<name>.json, its report in $WORK/probe.out.
watch() {
  "$PROBE" settle --url "$URL" --out-dir "$WORK" --timeout 120 "$@" >"$WORK/probe.out" 2>&1 &
  PID[probe]=$!
  wait_for_line "$WORK/probe.out" ready || fail "fleet_probe did not start"
}
await_settled() {
  wait "${PID[probe]}" || fail "fleet did not settle: $(cat "$WORK/probe.out")"
  unset 'PID[probe]'
  cat "$WORK/probe.out"
}

# The current plan id of robot PREFIX in the last probe report.
current_plan() { sed -n "s/^$1: plan \([0-9]*\).*/\1/p" "$WORK/probe.out"; }

# with_goal SCENE Q NAME: a copy of the scene (paths made absolute) whose goal is Q, for
# validating a plan of a goal sent over LCM; prints its path.
with_goal() {
  local out="$WORK/$3.yaml"
  sed -e "s|: \.\./|: $(dirname "$1")/../|" \
      -e "/^goal:/,/^[a-z]/ s|^  q: .*|  q: [$2]|" "$1" >"$out"
  echo "$out"
}

# check_plans NAME=SCENE ...: each plan validates against its scene (from its first knot: a
# robot without states replans from where its plan in force has it), and together they keep
# clear at and between the knots.
check_plans() {
  local args=() item
  for item in "$@"; do
    "$KG" validate --start-from-plan "${item#*=}" "$WORK/${item%%=*}.json" \
      >"$WORK/validate.out" 2>&1 \
      || fail "${item%%=*}'s plan does not validate: $(grep -A3 failures "$WORK/validate.out")"
    args+=("${item#*=}" "$WORK/${item%%=*}.json")
  done
  "$KG" check-together "${args[@]}" || fail "the plans are not clear of each other"
}
