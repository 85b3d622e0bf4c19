#!/usr/bin/env bash
# The main job: installs dependencies, builds, and runs the demo, writing its output to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
mkdir -p out
KG=./build/tools/kinograph
$KG info robots/iiwa14/iiwa14.urdf
$KG info robots/acrobot/acrobot.urdf

# Plan every shipped scene into out/<scene>.json. `kinograph plan` exits 2 for a plan that does
# not validate; the demo reports it and goes on (the plan file is written either way).
plan() {
  local name=$1
  echo "== plan robots/scenes/$name.yaml"
  local rc=0
  $KG plan "robots/scenes/$name.yaml" --out "out/$name.json" || rc=$?
  if [ "$rc" -eq 2 ]; then
    echo "   ($name: the plan does not validate; see the figures above)"
  elif [ "$rc" -ne 0 ]; then
    exit "$rc"
  fi
  $KG validate "robots/scenes/$name.yaml" "out/$name.json" >/dev/null 2>&1 || true
}
for scene in acrobot_swingup rr_reach iiwa_desk iiwa_min_torque; do
  plan "$scene"
done

# Pictures, when the renderer's verbs are built: an Acrobot 20-frame strip, 5-frame strips of
# the other plans, and task 2's joint torques with and without the minimum-torque objective
# (iiwa_desk.yaml is the same move without it).
if $KG render --help >/dev/null 2>&1; then
  $KG render out/acrobot_swingup.json --frames 20 \
    --width 4000 --height 420 --out out/acrobot_swingup_strip.png
  for scene in rr_reach iiwa_desk iiwa_min_torque; do
    $KG render "out/$scene.json" --scene "robots/scenes/$scene.yaml" --frames 5 \
      --out "out/${scene}_strip.png"
  done
fi
if $KG plot --help >/dev/null 2>&1; then
  $KG plot out/iiwa_min_torque.json out/iiwa_desk.json --label "with min torque" \
    --label "without min torque" --title "iiwa task 2: joint torques" \
    --out out/iiwa_task2_torque.png
fi
# The replanning figure: the desk plan, then a ball appears on the block's way up
# (robots/scenes/changes/iiwa_desk_ball.yaml) and the plan is replanned incrementally; both in
# one view (first plan grey, replan in colour, the new obstacle highlighted).
if $KG render --help 2>/dev/null | grep -- --compare >/dev/null; then
  echo "== replan robots/scenes/iiwa_desk.yaml + changes/iiwa_desk_ball.yaml"
  rm -f out/iiwa_desk_replan_before.json out/iiwa_desk_replan_after.json
  rc=0
  $KG replan robots/scenes/iiwa_desk.yaml robots/scenes/changes/iiwa_desk_ball.yaml \
    --out-before out/iiwa_desk_replan_before.json --out-after out/iiwa_desk_replan_after.json \
    --quiet || rc=$?
  if [ "$rc" -eq 2 ]; then
    echo "   (iiwa_desk replan: a plan does not validate; the figure shows it anyway)"
  elif [ "$rc" -ne 0 ]; then
    exit "$rc"
  fi
  if [ -f out/iiwa_desk_replan_after.json ]; then
    $KG render out/iiwa_desk_replan_before.json --compare out/iiwa_desk_replan_after.json \
      --scene robots/scenes/iiwa_desk.yaml --frames 5 --width 1000 --height 800 \
      --after-label "after the change (replanned): robot colours, red path" \
      --out out/iiwa_desk_replan.png
  fi
fi

# Two iiwa arms crossing over a table, planned together in one factor graph (out/cell/): one
# plan file per arm, a strip and a ghost view with each arm in its own colour.
echo "== plan-cell robots/cells/two_iiwa_table.yaml"
rc=0
$KG plan-cell robots/cells/two_iiwa_table.yaml --out out/cell || rc=$?
if [ "$rc" -eq 2 ]; then
  echo "   (two_iiwa_table: the plan does not validate; the pictures show it anyway)"
elif [ "$rc" -ne 0 ]; then
  exit "$rc"
fi
$KG render-cell robots/cells/two_iiwa_table.yaml out/cell --out out/cell/two_iiwa_table_strip.png
$KG render-cell robots/cells/two_iiwa_table.yaml out/cell --style ghost \
  --width 1000 --height 700 --out out/cell/two_iiwa_table_ghost.png

# The daemon end to end over LCM: a goal, then an obstacle that forces a replan (out/daemon/).
echo "== daemon demo (kinographd over LCM)"
./scripts/daemon_demo.sh || echo "   (daemon demo: a plan did not validate; see out/daemon/kinographd.log)"
# The loop closed: daemon, executor and simulated iiwa; a ball appears while the arm moves
# (out/closed_loop/).
echo "== closed-loop demo (kinographd, kinograph execute, kinograph sim over LCM)"
./scripts/closed_loop_demo.sh || echo "   (closed-loop demo failed; see out/closed_loop/*.log)"
ls -l out/ out/cell/ out/daemon/ out/closed_loop/
