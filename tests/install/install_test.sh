#!/usr/bin/env bash
# The installed package as a user gets it. Installs the build into a temporary prefix, builds
# examples/ against it with find_package(kinograph 0.1) and runs it; then, with the prefix
# moved, the installed CLI plans, validates and renders a shipped scene (and the installed
# Python client publishes a goal) from another working directory with the build and source trees gone: empty directories are mounted over them in a
# private mount namespace.
# That needs root; without it the last step is skipped (exit 77) and says so.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
BUILD=$(cd "$1" && pwd)
SRC=$(cd "$2" && pwd)
TMP=$(mktemp -d /tmp/kinograph_install_test.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
PREFIX=$TMP/prefix
case "$TMP" in "$SRC"/* | "$BUILD"/*) echo "FAIL: $TMP lies inside the trees it must hide"; exit 1 ;; esac

cmake --install "$BUILD" --prefix "$PREFIX" >"$TMP/install.log"
for f in bin/kinograph bin/kinographd bin/kinograph-spy include/kinograph/kinograph/goal_t.hpp \
         include/kinograph/kinograph/planning/io/scene.h include/kinograph/render/image.h \
         lib/cmake/kinograph/kinographConfig.cmake lib/cmake/kinograph/kinographConfigVersion.cmake \
         share/kinograph/robots/scenes/rr_reach.yaml share/kinograph/lcmtypes/goal_t.lcm \
         share/kinograph/python/kinograph/plan_t.py share/kinograph/python/kinograph_client/client.py \
         share/doc/kinograph/LICENSE; do
  [ -e "$PREFIX/$f" ] || { echo "FAIL: $f was not installed"; exit 1; }
done
# Nothing installed may point back into the trees it came from.
if grep -rlF -e "$SRC" -e "$BUILD" "$PREFIX" >"$TMP/refs"; then
  echo "FAIL: installed files name the source or build tree:"; cat "$TMP/refs"; exit 1
fi

# The downstream project, with the build's compiler launcher (ccache) when it has one.
launcher=$(sed -n 's/^CMAKE_CXX_COMPILER_LAUNCHER:[A-Z]*=//p' "$BUILD/CMakeCache.txt")
cmake -S "$SRC/examples" -B "$TMP/examples" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$PREFIX" ${launcher:+-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher} \
  >"$TMP/examples-configure.log" || { cat "$TMP/examples-configure.log"; exit 1; }
cmake --build "$TMP/examples" >"$TMP/examples-build.log" || { cat "$TMP/examples-build.log"; exit 1; }
"$TMP/examples/robot_info" "$PREFIX/share/kinograph/robots/iiwa14/iiwa14.urdf" | tee "$TMP/info.txt"
grep -q "robot 'iiwa14': 7 joints" "$TMP/info.txt" || { echo "FAIL: robot_info"; exit 1; }
# Outside the prefix a program knows the data directory through KINOGRAPH_DATA_DIR; with it,
# the plan file names the robot relative to it.
KINOGRAPH_DATA_DIR="$PREFIX/share/kinograph" "$TMP/examples/plan_from_code" "$TMP/from_code.json"
grep -q '"urdf": "robots/rr/rr.urdf"' "$TMP/from_code.json" ||
  { echo "FAIL: the plan file does not name the robot relative to the data directory"; exit 1; }

# A version the package does not promise is refused.
mkdir -p "$TMP/v2"
cat >"$TMP/v2/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(v2 LANGUAGES CXX)
find_package(kinograph 1.0 REQUIRED)
CM
if cmake -S "$TMP/v2" -B "$TMP/v2/build" -DCMAKE_PREFIX_PATH="$PREFIX" >"$TMP/v2.log" 2>&1; then
  echo "FAIL: find_package(kinograph 1.0) accepted version 0.x"; exit 1
fi

# The installed CLI with the trees hidden, from a working directory of its own, after the
# prefix has moved (nothing may depend on where it was installed).
mv "$PREFIX" "$TMP/moved"
PREFIX=$TMP/moved
mkdir -p "$TMP/moved_user"
cat >"$TMP/moved_user/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.18)
project(moved_user LANGUAGES CXX)
find_package(kinograph 0.1 REQUIRED)
message(STATUS "data: ${kinograph_DATA_DIR}")
CM
cmake -S "$TMP/moved_user" -B "$TMP/moved_user/build" -DCMAKE_PREFIX_PATH="$PREFIX" >"$TMP/moved.log" 2>&1 ||
  { cat "$TMP/moved.log"; echo "FAIL: find_package(kinograph) in the moved prefix"; exit 1; }
grep -qF -- "-- data: $PREFIX/share/kinograph" "$TMP/moved.log" ||
  { cat "$TMP/moved.log"; echo "FAIL: kinograph_DATA_DIR does not follow the moved prefix"; exit 1; }
mkdir -p "$TMP/work"
cat >"$TMP/cli.sh" <<CLI
set -eu
cd "$TMP/work"
test ! -e "$SRC/robots"
test ! -e "$BUILD/CMakeCache.txt"
env -u KINOGRAPH_DATA_DIR "$PREFIX/bin/kinograph" plan "$PREFIX/share/kinograph/robots/scenes/rr_reach.yaml" --out plan.json
env -u KINOGRAPH_DATA_DIR "$PREFIX/bin/kinograph" validate "$PREFIX/share/kinograph/robots/scenes/rr_reach.yaml" plan.json
env -u KINOGRAPH_DATA_DIR "$PREFIX/bin/kinograph" render plan.json --frames 3 --width 600 --height 200 --out strip.png
[ -s strip.png ]
grep -q '"urdf": "robots/rr/rr.urdf"' plan.json
grep -q '"scene": "robots/scenes/rr_reach.yaml"' plan.json
# The installed Python types and client: a goal encoded and published (in-process memq).
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$PREFIX/share/kinograph/python" python3 -c \
  "from kinograph_client import PlannerClient, joint_goal; PlannerClient('RR', 'memq://').send(joint_goal([0.1, 0.2]))"
CLI
if [ "$(id -u)" -ne 0 ] || ! unshare -m true 2>/dev/null; then
  echo "SKIP: hiding the source and build trees needs root (a private mount namespace)"
  exit 77
fi
unshare -m sh -c "mount -t tmpfs none '$BUILD' && mount -t tmpfs none '$SRC' && sh '$TMP/cli.sh'"
echo "install test: passed"
