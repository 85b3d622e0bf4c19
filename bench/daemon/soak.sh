#!/usr/bin/env bash
# A mixed soak of kinographd over real UDP multicast in a private network namespace (not in
# CI): for MINUTES (default 30) a client sends goals at 2 Hz, obstacle moves at 30 Hz and
# measured states at 100 Hz (RR arm, tests/integration/rr_daemon.yaml, with a state file),
# while the daemon's resident memory is sampled every 60 s. At the end it prints the client's
# figures (goals answered, planned, superseded, lost, answer latency, longest heartbeat gap)
# and the daemon's memory at the start and end, and writes them to JSON_OUT if given.
# Usage (as root): bench/daemon/soak.sh BUILD_DIR SOURCE_DIR [MINUTES] [JSON_OUT]
set -euo pipefail
BUILD=$1
SRC=$2
MINUTES=${3:-30}
OUT=${4:-}
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7713?ttl=0&recv_buf_size=4194304"
rss_kb() { awk '/VmRSS/ {print $2}' "/proc/$1/status"; }

start_daemon "$SRC/tests/integration/rr_daemon.yaml" "$URL" "$WORK/daemon.log" \
  --state-file "$WORK/rr.state"
RSS0=$(rss_kb "$DAEMON")
( while kill -0 "$DAEMON" 2>/dev/null; do rss_kb "$DAEMON" >>"$WORK/rss.txt"; sleep 60; done ) \
  </dev/null >/dev/null 2>&1 &
SAMPLER=$!
PIDS+=($SAMPLER)
GOALS=$((MINUTES * 60 * 2))
"$STORM" --url "$URL" --prefix RR --goals "$GOALS" --rate 2 --obstacle-rate 30 \
  --state-rate 100 --state-q -0.8,0.4 --state-joints joint1,joint2 --answer-timeout 120 \
  --json "$WORK/soak.json" >"$WORK/soak.out" 2>&1 || STATUS=$?
kill "$SAMPLER" 2>/dev/null || true
RSS1=$(rss_kb "$DAEMON")
cat "$WORK/soak.out"
SERIES=$(paste -sd, "$WORK/rss.txt")
echo "daemon RSS: $RSS0 kB at start, $RSS1 kB at the end; every 60 s: $SERIES"
echo "daemon log: $(wc -l <"$WORK/daemon.log") lines, $(grep -c "\\[warning\\]\\|\\[error\\]" "$WORK/daemon.log" || true) warnings or errors"
[ -z "$OUT" ] || sed "s/}\$/, \"minutes\": $MINUTES, \"rss_kb_start\": $RSS0, \"rss_kb_end\": $RSS1, \"rss_kb_every_60s\": [$SERIES]}/" \
  "$WORK/soak.json" >"$OUT"
[ "${STATUS:-0}" = 0 ] || fail "the client found goals answered wrongly or not at all"
