#!/usr/bin/env bash
# The distributed half of multi_robot_bench on the first two 2-arm cells of seed 1, over udpm in
# a private network namespace: p00 settles after arm0, refused at first (its goal is where arm1
# stands), tries again along arm1's plan, and p01 settles; the centralized-only run of the same
# cells merges into one row per problem; --distributed-timeout is obeyed; with daemons that
# refuse every goal (through --kinographd) the fleet, idle, is given up after --quiet; without a
# multicast route the bench refuses.
# Usage: distributed_runs_test.sh BUILD_DIR SOURCE_DIR. Exit 77 when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
BENCH="$BUILD/bench/multi_robot/multi_robot_bench"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}
run() { "$BENCH" --robots 2 --problems 2 --seed 1 --cells-dir "$WORK/cells" "$@"; }

run --distributed-only --out "$WORK/d.json" >"$WORK/d.out" 2>"$WORK/d.err" \
  || fail "distributed run: $(cat "$WORK/d.err")"
cat "$WORK/d.err"
grep -q "^iiwa2_p00 distributed: ok clear after [0-9.]* s, settled after [0-9.]* s, [2-9] replans" \
  "$WORK/d.err" || fail "p00 did not settle after arm0 tried its blocked goal again"
# arm1 yields to arm0's first plan (0 replans) or, when arm0's announcement comes later than
# arm1's listen, replans around it.
grep -q "^iiwa2_p01 distributed: ok clear after [0-9.]* s, settled after [0-9.]* s, [0-9]* replans" \
  "$WORK/d.err" || fail "p01 did not settle"
grep -q "centralized" "$WORK/d.err" && fail "--distributed-only planned centrally"

run --centralized-only --out "$WORK/c.json" >/dev/null 2>"$WORK/c.err" \
  || fail "centralized run: $(cat "$WORK/c.err")"
"$BENCH" --report "$WORK/c.json,$WORK/d.json" --table "$WORK/t.md" --plot "$WORK/p.png" \
  >/dev/null || fail "--report"
cat "$WORK/t.md"
grep -q "^| 2 | 2 | 2/2 | [^|]* | [^|]* | 2/2 |" "$WORK/t.md" \
  || fail "the two halves of the same cells did not merge into one row"
[ -s "$WORK/p.png" ] || fail "no plot"

run --distributed-only --distributed-timeout 0.01 --out "$WORK/t.json" >/dev/null \
  2>"$WORK/t.err" || fail "timeout run: $(cat "$WORK/t.err")"
[ "$(grep -c "distributed: FAILED .*not settled within 0.01 s" "$WORK/t.err")" = 2 ] \
  || fail "--distributed-timeout 0.01 was not obeyed: $(cat "$WORK/t.err")"

# Daemons whose scenes give a horizon too short for any move refuse every goal at once: the
# fleet, idle and not settled, is given up after --quiet, long before --distributed-timeout.
cat >"$WORK/refusing" <<EOF
#!/bin/sh
scene=\$1
shift
grep -v '^horizon:' "\$scene" >"\${scene%.yaml}_short.yaml"
echo 'horizon: 0.05' >>"\${scene%.yaml}_short.yaml"
exec "$BUILD/daemon/kinographd" "\${scene%.yaml}_short.yaml" "\$@"
EOF
chmod +x "$WORK/refusing"
"$BENCH" --robots 2 --problems 1 --seed 1 --cells-dir "$WORK/cells" --distributed-only \
  --kinographd "$WORK/refusing" --quiet 0.5 --distributed-timeout 120 --out "$WORK/q.json" \
  >/dev/null 2>"$WORK/q.err" || fail "quiet run: $(cat "$WORK/q.err")"
grep -q "^iiwa2_p00 distributed: FAILED .*no daemon planning and no plan for 0.5 s, not settled" \
  "$WORK/q.err" || fail "the idle fleet was not given up after --quiet 0.5 s: $(cat "$WORK/q.err")"

if unshare -n "$BENCH" --robots 2 --problems 1 --out "$WORK/n.json" >/dev/null \
  2>"$WORK/n.err"; then
  fail "ran without a multicast route"
fi
grep -q "private network namespace with multicast routed" "$WORK/n.err" \
  || fail "no clear refusal without a multicast route: $(cat "$WORK/n.err")"
echo "PASS"
