#!/usr/bin/env bash
# `kinograph check-together`: the pair scenes' arms planned alone collide (exit 2, naming both
# robots and the depth); the same plans 10 s apart on the common clock, by --start or by the
# files' start_utime, are clear (exit 0); bad input is 1, a malformed command line 64.
# Usage: check_together_test.sh BUILD_DIR SOURCE_DIR.
set -euo pipefail
KG="$1/tools/kinograph"
SCENES="$2/robots/scenes"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
L="$SCENES/iiwa_pair_left.yaml"
R="$SCENES/iiwa_pair_right.yaml"
"$KG" plan "$L" --out "$WORK/left.json" >/dev/null
"$KG" plan "$R" --out "$WORK/right.json" >/dev/null

code=0
"$KG" check-together "$L" "$WORK/left.json" "$R" "$WORK/right.json" >"$WORK/out" 2>&1 || code=$?
[ "$code" = 2 ] || fail "colliding plans: exit $code, expected 2: $(cat "$WORK/out")"
grep -q "robots 'iiwa_pair_left' (link '[a-z_0-9]*') and 'iiwa_pair_right' (link '[a-z_0-9]*') overlap by" \
  "$WORK/out" || fail "the collision is not named: $(cat "$WORK/out")"

"$KG" check-together "$L" "$WORK/left.json" "$R" "$WORK/right.json" --start 0,10 >"$WORK/out" 2>&1 \
  || fail "plans 10 s apart are not clear: $(cat "$WORK/out")"
# The same by start_utime in the files (µs), as send-goal writes them.
sed 's/^{/{"start_utime": 1000000,/' "$WORK/left.json" >"$WORK/left_t.json"
sed 's/^{/{"start_utime": 11000000,/' "$WORK/right.json" >"$WORK/right_t.json"
"$KG" check-together "$L" "$WORK/left_t.json" "$R" "$WORK/right_t.json" >"$WORK/out" 2>&1 \
  || fail "plans 10 s apart by start_utime are not clear: $(cat "$WORK/out")"
grep -q "right_t.json from t = 10 s to 13 s" "$WORK/out" || fail "start_utime not used: $(cat "$WORK/out")"

code=0
"$KG" check-together "$L" "$WORK/left.json" "$R" "$WORK/none.json" >"$WORK/out" 2>&1 || code=$?
[ "$code" = 1 ] || fail "a missing plan: exit $code, expected 1"
code=0
"$KG" check-together "$L" "$WORK/left.json" "$R" >"$WORK/out" 2>&1 || code=$?
[ "$code" = 64 ] || fail "an odd number of files: exit $code, expected 64"
code=0
"$KG" check-together "$L" "$WORK/left.json" "$R" "$WORK/right.json" --start 0 >"$WORK/out" 2>&1 \
  || code=$?
[ "$code" = 1 ] || fail "--start with one time for two robots: exit $code, expected 1"
echo "1 passed, 0 failed"
