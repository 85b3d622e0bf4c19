#!/usr/bin/env bash
# A goal storm over real UDP multicast: goals at 1 kHz and obstacle moves at 200 Hz for
# SECONDS (default 2.5; the 60 s run of docs/reliability.md is this script with 60), and every
# goal must be answered exactly once (planned or SUPERSEDED), the last one by a valid plan, and
# the daemon's heartbeat must account for all of them (its counts include the 1 s warm-up).
# Prints the client's figures (JSON) and the daemon's resident memory before and after.
# Usage: storm_test.sh BUILD_DIR SOURCE_DIR [SECONDS] [SCENE] [Q] [JSON_OUT] [WARMUP_SECONDS]
set -euo pipefail
BUILD=$1
SRC=$2
SECONDS_=${3:-2.5}
SCENE=${4:-$SRC/tests/integration/rr_daemon.yaml}
Q=${5:-0.8,-0.4}
OUT=${6:-}
WARMUP=${7:-1}
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7712?ttl=0&recv_buf_size=8388608"
rss_kb() { awk '/VmRSS/ {print $2}' "/proc/$1/status"; }

start_daemon "$SCENE" "$URL" "$WORK/daemon.log"
# Warm up with a short storm (the planner, its obstacle and LCM's buffers built), so that the
# memory figure compares steady states; the resident memory is sampled every 10 s.
WARM_GOALS=$(awk -v s="$WARMUP" 'BEGIN { printf "%d", s * 1000 }')
"$STORM" --url "$URL" --prefix RR --goals "$WARM_GOALS" --first-id 1 --rate 1000 \
  --obstacle-rate 200 --q "$Q" --answer-timeout 120 >"$WORK/warmup.out" 2>&1 \
  || { cat "$WORK/warmup.out"; fail "warm-up storm not answered"; }
RSS0=$(rss_kb "$DAEMON")
( while kill -0 "$DAEMON" 2>/dev/null; do rss_kb "$DAEMON" >>"$WORK/rss.txt"; sleep 10; done ) \
  </dev/null >/dev/null 2>&1 &
SAMPLER=$!
PIDS+=($SAMPLER)
GOALS=$(awk -v s="$SECONDS_" 'BEGIN { printf "%d", s * 1000 }')
"$STORM" --url "$URL" --prefix RR --goals "$GOALS" --first-id $((WARM_GOALS + 1)) --rate 1000 \
  --obstacle-rate 200 --q "$Q" --answer-timeout 120 --json "$WORK/storm.json" \
  >"$WORK/storm.out" 2>&1 || { cat "$WORK/storm.out"; fail "storm: not every goal answered as it should be"; }
kill "$SAMPLER" 2>/dev/null || true
RSS1=$(rss_kb "$DAEMON")
cat "$WORK/storm.out"
SERIES=$(paste -sd, "$WORK/rss.txt")
echo "daemon RSS: $RSS0 kB after warm-up, $RSS1 kB after the storm; every 10 s: $SERIES"
[ -z "$OUT" ] || sed "s/}\$/, \"warmup_s\": $WARMUP, \"rss_kb_before\": $RSS0, \"rss_kb_after\": $RSS1, \"rss_kb_every_10s\": [$SERIES]}/" \
  "$WORK/storm.json" >"$OUT"
grep -q "\"answered\": $GOALS," "$WORK/storm.json" || fail "not all $GOALS goals answered"
echo "1 passed, 0 failed"
