#!/usr/bin/env bash
# Builds the API reference and fails on any Doxygen warning, printing them.
# Usage: doxygen_test.sh DOXYGEN DOXYFILE WARNINGS_LOG HTML_DIR
set -euo pipefail
DOXYGEN=$1
DOXYFILE=$2
WARNINGS=$3
HTML=$4
rm -f "$WARNINGS"
"$DOXYGEN" "$DOXYFILE"
[ -s "$HTML/index.html" ] || { echo "FAIL: no $HTML/index.html"; exit 1; }
grep -q "PlannerNode" "$HTML/annotated.html" || { echo "FAIL: PlannerNode not in the reference"; exit 1; }
if [ -s "$WARNINGS" ]; then
  echo "FAIL: Doxygen warnings:"
  cat "$WARNINGS"
  exit 1
fi
echo "1 passed, 0 failed: $(ls "$HTML" | wc -l) files, no warning"
