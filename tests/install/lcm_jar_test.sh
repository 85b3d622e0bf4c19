#!/usr/bin/env bash
# The lcm-spy jar holds every struct of every .lcm file, kinograph's and Drake's (drake/), and
# kinograph-spy's class path finds both them and lcm-spy itself. Skipped (exit 77) with a
# message when the jar was not built.
# Usage: lcm_jar_test.sh JAR SPY_LAUNCHER LCMTYPES_DIR
set -euo pipefail
jar=$1 spy=$2
# package.type of each struct, from the file's own package line.
classes=()
for file in "$3"/*.lcm "$3"/drake/*.lcm; do
  package=$(sed -n 's/^package \([A-Za-z0-9_]*\);.*/\1/p' "$file")
  [ -n "$package" ] || { echo "FAIL: $file names no package"; exit 1; }
  while read -r type; do classes+=("$package.$type"); done \
    < <(sed -n 's/^struct \([A-Za-z0-9_]*\).*/\1/p' "$file")
done
[ ${#classes[@]} -gt 0 ] || { echo "FAIL: no struct found in $3"; exit 1; }
grep -qx 'drake\..*' < <(printf '%s\n' "${classes[@]}") ||
  { echo "FAIL: no Drake type found in $3/drake"; exit 1; }
if [ ! -f "$jar" ]; then
  echo "SKIP: $jar was not built (needs a JDK and liblcm-java at configure time)"
  exit 77
fi
listing=$(unzip -l "$jar")
for class in "${classes[@]}"; do
  path="${class//.//}.class"
  grep -q " $path$" <<<"$listing" || { echo "FAIL: $path is not in $jar"; exit 1; }
done
echo "all ${#classes[@]} types (kinograph's and Drake's) in $jar"
classpath=$(KINOGRAPH_LCM_JAR="$jar" "$spy" --classpath)
javap -cp "$classpath" lcm.spy.Spy "${classes[@]}" >/dev/null
echo "kinograph-spy's class path loads lcm.spy.Spy and every type"
