#!/usr/bin/env bash
# docs/tutorial_own_robot.md, run: the KR5 of Debian's dart-doc is planned from its scene
# (robots/scenes/kr5_reach.yaml), validated and rendered, and without the scene's limits and
# allowed collision it is refused saying why. Exit 77 (skipped) when dart-doc is not installed.
# Usage: tutorial_own_robot_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
KG="$1/tools/kinograph"
SCENE="$2/robots/scenes/kr5_reach.yaml"
URDF="/usr/share/doc/dart/data/urdf/KR5/KR5 sixx R650.urdf"
[ -f "$URDF" ] || { echo "SKIP: $URDF not found (Debian package dart-doc)"; exit 77; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$KG" info "$URDF" >"$WORK/info.txt" 2>&1 || fail "info: $(cat "$WORK/info.txt")"
grep -q "effort=\"0\" read as unknown" "$WORK/info.txt" || fail "info does not warn of effort=0"
grep -q "6 joints" "$WORK/info.txt" || fail "info: not 6 joints"

"$KG" plan "$SCENE" --out "$WORK/kr5.json" >"$WORK/plan.txt" 2>&1 || fail "plan: $(cat "$WORK/plan.txt")"
grep -q "^success: yes" "$WORK/plan.txt" || fail "not a success: $(cat "$WORK/plan.txt")"
grep -q "^validation: valid" "$WORK/plan.txt" || fail "not valid: $(cat "$WORK/plan.txt")"
"$KG" validate "$SCENE" "$WORK/kr5.json" >/dev/null 2>&1 || fail "the plan file does not validate"
"$KG" render "$WORK/kr5.json" --frames 4 --width 800 --height 200 --out "$WORK/kr5.png" \
  >/dev/null 2>&1 || fail "render"
[ -s "$WORK/kr5.png" ] || fail "no picture"

# Without allowed_collisions the start is refused, naming the two links.
sed '/allowed_collisions/,$d' "$SCENE" > "$WORK/no_allowed.yaml"
set +e
"$KG" plan "$WORK/no_allowed.yaml" --out "$WORK/x.json" >"$WORK/out.txt" 2>&1
code=$?
set -e
[ "$code" -ne 0 ] || fail "the overlapping hulls were not refused"
grep -q "links 'forearm' and 'palm' overlap" "$WORK/out.txt" || fail "$(cat "$WORK/out.txt")"
echo "1 passed, 0 failed"
