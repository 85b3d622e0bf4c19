#!/usr/bin/env bash
# The price of a change on Table I, in interleaved pairs: a baseline planning_bench (run in its
# own source tree, so it plans its own scenes) and this build's, one after the other, PAIRS
# times in the same session. Prints each pair's task-1 and task-2 medians and their ratios, then
# the median ratio over the pairs. JSON of every run in OUT.
# Usage: bench/planning/price_pairs.sh BASELINE_BIN BASELINE_TREE [PAIRS] [OUT]
set -euo pipefail
cd "$(dirname "$0")/../.."
BASE_BIN=$1
BASE_TREE=$2
PAIRS=${3:-3}
OUT=${4:-out/price_pairs}
NEW_BIN=${KINOGRAPH_BUILD_DIR:-build}/bench/planning/planning_bench
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
median_of() { jq -r ".$2.time_s_median" "$1"; }
r1=() r2=()
echo "| pair | baseline task 1 (ms) | new task 1 (ms) | ratio | baseline task 2 (ms) | new task 2 (ms) | ratio | successes (base / new) |"
echo "|---|---|---|---|---|---|---|---|"
for i in $(seq "$PAIRS"); do
  (cd "$BASE_TREE" && "$BASE_BIN" --goals 50 --acrobot-repeats 5 --json "$OUT/base_$i.json" >/dev/null 2>&1)
  "$NEW_BIN" --goals 50 --acrobot-repeats 5 --json "$OUT/new_$i.json" >/dev/null 2>&1
  b1=$(median_of "$OUT/base_$i.json" iiwa_task1) n1=$(median_of "$OUT/new_$i.json" iiwa_task1)
  b2=$(median_of "$OUT/base_$i.json" iiwa_task2) n2=$(median_of "$OUT/new_$i.json" iiwa_task2)
  q1=$(awk -v a="$n1" -v b="$b1" 'BEGIN {printf "%.2f", a / b}')
  q2=$(awk -v a="$n2" -v b="$b2" 'BEGIN {printf "%.2f", a / b}')
  r1+=("$q1") r2+=("$q2")
  ok=$(for f in base new; do jq -r '"\(.iiwa_task1.successes)+\(.iiwa_task2.successes)"' "$OUT/${f}_$i.json"; done | paste -sd/)
  awk -v i="$i" -v b1="$b1" -v n1="$n1" -v q1="$q1" -v b2="$b2" -v n2="$n2" -v q2="$q2" -v ok="$ok" \
    'BEGIN {printf "| %d | %.0f | %.0f | %s | %.0f | %.0f | %s | %s |\n", i, b1*1e3, n1*1e3, q1, b2*1e3, n2*1e3, q2, ok}'
done
echo
echo "median ratio over $PAIRS pairs: task 1 $(printf '%s\n' "${r1[@]}" | median), task 2 $(printf '%s\n' "${r2[@]}" | median)"
