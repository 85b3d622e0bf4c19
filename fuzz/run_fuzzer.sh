#!/usr/bin/env bash
# One libFuzzer run of a fuzz target: run_fuzzer.sh FUZZER RUNS SECONDS SEED_DIR...
# RUNS inputs from a fixed seed (the same inputs on every machine), cut short after SECONDS.
# The seeds are read, never written: new inputs go to a fresh temporary corpus. A finding keeps
# that directory (its crash-*/timeout-*/oom-* file is the input) and fails; else it is removed.
set -euo pipefail
fuzzer=$1 runs=$2 seconds=$3
shift 3
work=$(mktemp -d "${TMPDIR:-/tmp}/kinograph-fuzz.XXXXXX")
mkdir -p "$work/corpus"
if "$fuzzer" -seed=1 -runs="$runs" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
     -artifact_prefix="$work/" "$work/corpus" "$@"; then
  rm -rf "$work"
else
  status=$?
  echo "run_fuzzer.sh: $(basename "$fuzzer") found an input that fails; kept in $work:" >&2
  ls "$work" >&2
  exit "$status"
fi
