#!/usr/bin/env bash
# The lcm-spy jar holds every struct of every .lcm file, and kinograph-spy's class path finds
# both them and lcm-spy itself. Skipped (exit 77) with a message when the jar was not built.
# Usage: lcm_jar_test.sh JAR SPY_LAUNCHER LCMTYPES_DIR
set -euo pipefail
jar=$1 spy=$2
mapfile -t types < <(sed -n 's/^struct \([A-Za-z0-9_]*\).*/\1/p' "$3"/*.lcm)
[ ${#types[@]} -gt 0 ] || { echo "FAIL: no struct found in $3/*.lcm"; exit 1; }
set -- "${types[@]}"
if [ ! -f "$jar" ]; then
  echo "SKIP: $jar was not built (needs a JDK and liblcm-java at configure time)"
  exit 77
fi
listing=$(unzip -l "$jar")
for type in "$@"; do
  grep -q " kinograph/$type.class$" <<<"$listing" || { echo "FAIL: kinograph/$type.class is not in $jar"; exit 1; }
done
echo "all $# types in $jar"
classpath=$(KINOGRAPH_LCM_JAR="$jar" "$spy" --classpath)
javap -cp "$classpath" lcm.spy.Spy "${@/#/kinograph.}" >/dev/null
echo "kinograph-spy's class path loads lcm.spy.Spy and every type"
