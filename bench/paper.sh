#!/usr/bin/env bash
# The paper's figures and the side-by-side comparisons, in one run on this machine:
#   Table I (Acrobot and iiwa tasks 1 and 2), Table II (DFGP-L, DFGP-W, iDFGP), the Acrobot
#   beside OMPL's SST, RRT and KPIECE1, kinograph's LM beside Ceres on the real iiwa task-1
#   graph, and the cost per iteration against the steps.
# Usage: bench/paper.sh [--quick] [BUILD_DIR [OUT_DIR]]
#   --quick   a few problems and seeds each (a check that everything runs, about 2-5 minutes)
#   BUILD_DIR a Release build with the benchmarks (default: build)
#   OUT_DIR   where the JSON, the Markdown tables and machine.txt go (default: out/paper)
set -euo pipefail
cd "$(dirname "$0")/.."
QUICK=0
if [ "${1:-}" = "--quick" ]; then QUICK=1; shift; fi
BUILD=${1:-build}
OUT=${2:-out/paper}
mkdir -p "$OUT"
for b in planning/planning_bench replanning/replanning_bench peers/graph_ceres_bench \
         scaling/scaling_bench; do
  [ -x "$BUILD/bench/$b" ] || { echo "paper.sh: $BUILD/bench/$b is not built" >&2; exit 1; }
done

# The ±4 N·m Acrobot gets fewer seeds: its OMPL searches mostly run to the cap, and 20 seeds
# of them alone would take about 20 minutes.
if [ $QUICK = 1 ]; then
  GOALS=3; REPEATS=2; PROBLEMS=2; SEEDS=2; SEEDS_4NM=1; CAP=3; SCALING=--quick; CERES_GOALS=3
else
  GOALS=50; REPEATS=20; PROBLEMS=20; SEEDS=20; SEEDS_4NM=6; CAP=20; SCALING=; CERES_GOALS=20
fi

{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ //')"
  echo "cores: $(nproc)"
  echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "os: $(. /etc/os-release && echo "$PRETTY_NAME")"
  echo "mode: $([ $QUICK = 1 ] && echo quick || echo full)"
} >"$OUT/machine.txt"

run() {  # run NAME COMMAND...: the table to NAME.md, the JSON to NAME.json (given by the caller)
  local name=$1; shift
  echo "== $name" >&2
  "$@" >"$OUT/$name.md" 2>"$OUT/$name.log"
}

run table1 "$BUILD/bench/planning/planning_bench" --goals $GOALS --acrobot-repeats $REPEATS \
  --json "$OUT/table1.json"
run table2 "$BUILD/bench/replanning/replanning_bench" --problems $PROBLEMS \
  --obstacle-problems $PROBLEMS --json "$OUT/table2.json"
if [ -x "$BUILD/bench/peers/acrobot_ompl_bench" ]; then
  run acrobot_vs_ompl "$BUILD/bench/peers/acrobot_ompl_bench" --seeds $SEEDS --cap $CAP \
    --settings 8nm --json "$OUT/acrobot_vs_ompl.json"
  run acrobot_vs_ompl_4nm "$BUILD/bench/peers/acrobot_ompl_bench" --seeds $SEEDS_4NM --cap $CAP \
    --settings 4nm --json "$OUT/acrobot_vs_ompl_4nm.json"
else
  echo "paper.sh: OMPL not found at configure time: the Acrobot comparison is skipped" >&2
fi
run lm_vs_ceres "$BUILD/bench/peers/graph_ceres_bench" --goals $CERES_GOALS \
  --json "$OUT/lm_vs_ceres.json"
run scaling "$BUILD/bench/scaling/scaling_bench" $SCALING --json "$OUT/scaling.json" \
  --png "$OUT/scaling.png"
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)" >>"$OUT/machine.txt"

for t in table1 table2 acrobot_vs_ompl acrobot_vs_ompl_4nm lm_vs_ceres scaling; do
  [ -f "$OUT/$t.md" ] || continue
  echo "## $t"
  grep '^|' "$OUT/$t.md" || true
  echo
done >"$OUT/README.md"
echo "paper.sh: tables in $OUT/README.md, machine in $OUT/machine.txt" >&2
