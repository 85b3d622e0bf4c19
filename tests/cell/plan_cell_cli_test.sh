#!/bin/sh
# kinograph plan-cell on a cell: exit 0, one plan and one scene per robot that `kinograph
# validate` accepts on its own, the composite plan, and render-cell's strip and ghost PNGs.
# Usage: plan_cell_cli_test.sh KINOGRAPH CELL ROBOT...
set -eu
kinograph=$1 cell=$2
shift 2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$kinograph" plan-cell "$cell" --out "$out/plans"
test -s "$out/plans/cell.json"
grep -q '"cell"' "$out/plans/cell.json"
for robot in "$@"; do
  "$kinograph" validate "$out/plans/$robot.yaml" "$out/plans/$robot.json" > /dev/null
  grep -q '"base"' "$out/plans/$robot.json"
done
"$kinograph" render-cell "$cell" "$out/plans" --frames 3 --width 600 --height 200 --out "$out/strip.png"
"$kinograph" render-cell "$cell" "$out/plans" --style ghost --width 400 --height 300 --out "$out/ghost.png"
for png in strip ghost; do
  test "$(head -c 8 "$out/$png.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a
done
echo "plan-cell: all robots valid"
