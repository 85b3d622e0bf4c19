#!/usr/bin/env bash
# Trying a blocked goal again (docs/multi_robot.md): two planar RR arms in one plane, one
# kinographd each over real UDP multicast in a private network namespace. 'hanging' gets the
# earlier goal (higher priority), with its tip where 'upright' stands (fleet_rr_upright.yaml):
# refused, blocked by 'upright' held at its state. 'upright' then plans its own goal, leaning away
# in 3 s; 'hanging' tries its goal again with 'upright' moving along that plan, holds its start
# until 'upright' has left, and 'upright' replans around the plan of 'hanging', now the higher
# one. Both get measured states stamped on one robot clock, so every plan time is exact. Checked:
# the refusal names 'upright', the retry is logged as one, the settled plans validate and keep
# clear together, and 'hanging' starts when 'upright''s motion ends. Then the other order: the
# lower arm refused before the higher arm's plan came plans again when it comes.
# Usage: fleet_unblock_udpm_test.sh BUILD_DIR SOURCE_DIR. Exit 77 (skipped) when not root.
set -euo pipefail
BUILD=$1
SRC=$2
source "$SRC/tests/lib/private_netns.sh"
URL="udpm://239.255.76.67:7715?ttl=0&recv_buf_size=8388608"
source "$SRC/tests/integration/fleet_lib.sh"

UPRIGHT="$SRC/tests/integration/fleet_rr_upright.yaml"
HANGING="$SRC/tests/integration/fleet_rr_hanging.yaml"
start_utime() { sed -n 's/^ *"start_utime": \([0-9]*\).*/\1/p' "$1"; }

start_robot hanging "$HANGING" --neighbour "upright=$UPRIGHT"
start_robot upright "$UPRIGHT" --neighbour "hanging=$HANGING"
T=1000000000000
"$KG" send-state --prefix UPRIGHT --lcm-url "$URL" --scene "$UPRIGHT" --q 0,0 --utime $T
"$KG" send-state --prefix HANGING --lcm-url "$URL" --scene "$HANGING" --q 0,0 --utime $T
watch --robot "HANGING=$HANGING" --robot "UPRIGHT=$UPRIGHT"

"$KG" send-goal --prefix HANGING --lcm-url "$URL" --id 1 --q=-0.767,0 --wait 120 \
  --utime $((T + 100)) >"$WORK/hanging_refused.out" 2>&1 \
  && fail "hanging planned into upright: $(cat "$WORK/hanging_refused.out")"
grep -q "FAILED (blocked by neighbour 'upright' \[UPRIGHT\], held at its state" \
  "$WORK/hanging_refused.out" \
  || fail "hanging's refusal does not name upright: $(cat "$WORK/hanging_refused.out")"
echo "PASS: the higher arm's goal is refused, blocked by the lower arm held at its start"

send_goal upright 1 "-1.0,0" "$UPRIGHT" $((T + 200))
await_settled
grep -q "replanning: neighbour 'upright', which blocked the goal, has plan 1: trying again" \
  "$WORK/hanging.log" || fail "hanging did not try again for upright's plan"
check_plans "hanging=$HANGING" "upright=$UPRIGHT"
[ "$(start_utime "$WORK/upright.json")" = "$T" ] || fail "upright's plan does not start at the state"
[ "$(start_utime "$WORK/hanging.json")" = "$((T + 3000000))" ] \
  || fail "hanging's plan starts at $(start_utime "$WORK/hanging.json"), not when upright's ends"
echo "PASS: the higher arm tries again once the lower one has planned, and waits for it to leave"

# 2. Fresh daemons; 'upright' leans towards 'hanging', into where it hangs, and is refused before
# 'hanging', with the earlier goal, has planned; 'hanging' then swings away in 1 s, and 'upright'
# plans again around that plan, holding its start until 'hanging' has left.
for name in hanging upright; do
  kill -TERM "${PID[$name]}"
  wait "${PID[$name]}" || fail "$name did not stop cleanly"
  unset "PID[$name]"
done
rm -f "$WORK/hanging.json" "$WORK/upright.json"
start_robot hanging "$HANGING" --neighbour "upright=$UPRIGHT"
start_robot upright "$UPRIGHT" --neighbour "hanging=$HANGING"
T=$((T + 10000000))
"$KG" send-state --prefix UPRIGHT --lcm-url "$URL" --scene "$UPRIGHT" --q 0,0 --utime $T
"$KG" send-state --prefix HANGING --lcm-url "$URL" --scene "$HANGING" --q 0,0 --utime $T
watch --robot "HANGING=$HANGING" --robot "UPRIGHT=$UPRIGHT"
"$KG" send-goal --prefix UPRIGHT --lcm-url "$URL" --id 1 --q 0.8,0 --wait 120 \
  --utime $((T + 200)) >"$WORK/upright_refused.out" 2>&1 \
  && fail "upright planned into hanging: $(cat "$WORK/upright_refused.out")"
grep -q "FAILED (blocked by neighbour 'hanging' \[HANGING\], held at its state" \
  "$WORK/upright_refused.out" \
  || fail "upright's refusal does not name hanging: $(cat "$WORK/upright_refused.out")"
send_goal hanging 1 "0.8,0" "$HANGING" $((T + 100))
await_settled
check_plans "hanging=$(with_goal "$HANGING" "0.8, 0" hanging_away)" \
  "upright=$(with_goal "$UPRIGHT" "0.8, 0" upright_over)"
[ "$(start_utime "$WORK/hanging.json")" = "$T" ] || fail "hanging's plan does not start at the state"
[ "$(start_utime "$WORK/upright.json")" = "$((T + 1000000))" ] \
  || fail "upright's plan starts at $(start_utime "$WORK/upright.json"), not when hanging's ends"
echo "PASS: a goal refused before the higher arm's plan came is planned again when it comes"
echo "3 passed, 0 failed"
