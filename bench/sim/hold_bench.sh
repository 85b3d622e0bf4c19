#!/usr/bin/env bash
# The simulated iiwa (desk scene, 2 kg block) holding the scene's goal posture against gravity,
# commanded with the gravity torque of the planner's model, with the payload as the model has it
# and with it 10 % (0.2 kg) heavier: the largest deviation from the posture over 10 s (2001
# states) once within 0.05 rad of it for 1 s, and the simulator's CPU time per simulated second (its utime + stime
# over those 10 s). Real processes over udpm in a private network namespace.
# Prints one JSON object per case and a Markdown table. Usage, as root:
#   bash bench/sim/hold_bench.sh BUILD_DIR SOURCE_DIR [JSON_OUT]
set -euo pipefail
BUILD=$1
SRC=$2
OUT=${3:-}
source "$SRC/tests/integration/sim_lib.sh"
URL="udpm://239.255.76.67:7741?ttl=0&recv_buf_size=4194304"
ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat"; }
HZ=$(getconf CLK_TCK)
results=()
for mass in 0 0.2; do
  start_sim "$URL" --payload-mass-error "$mass"
  "$KG" send-command --prefix IIWA --lcm-url "$URL" --scene "$SCENE" --q "$GOAL" --gravity >/dev/null
  "$PROBE" wait-near --url "$URL" --channel IIWA_STATE --near "$GOAL" --tol 0.05 --count 200 \
    --timeout 120 >/dev/null || fail "the posture was not reached"
  c0=$(ticks "$SIM")
  "$PROBE" states --url "$URL" --channel IIWA_STATE --count 2001 --near "$GOAL" --timeout 120 \
    >"$WORK/hold.out" || fail "no states"
  c1=$(ticks "$SIM")
  span=$(( $(value "$WORK/hold.out" last_utime) - $(value "$WORK/hold.out" first_utime) ))
  cpu=$(awk -v c=$((c1 - c0)) -v hz="$HZ" -v s="$span" 'BEGIN { printf "%.3f", c / hz / (s / 1e6) }')
  dev=$(value "$WORK/hold.out" max_deviation)
  kill -INT "$SIM"
  wait "$SIM" || true
  results+=("{\"payload_mass_error_kg\": $mass, \"max_deviation_rad\": $dev, \"cpu_s_per_sim_s\": $cpu, \"states\": 2001}")
done
printf '%s\n' "${results[@]}"
[ -z "$OUT" ] || printf '[%s]\n' "$(IFS=,; echo "${results[*]}")" >"$OUT"
echo "| payload mass error | largest deviation over 10 s | simulator CPU per simulated s |"
echo "|---|---|---|"
for r in "${results[@]}"; do
  echo "$r" | sed -E 's/.*"payload_mass_error_kg": ([^,]*), "max_deviation_rad": ([^,]*), "cpu_s_per_sim_s": ([^,]*),.*/| \1 kg | \2 rad | \3 s |/'
done
