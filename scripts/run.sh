#!/usr/bin/env bash
# The main job: installs dependencies, builds, and runs the demo, writing its output to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
mkdir -p out
./build/tools/kinograph info robots/iiwa14/iiwa14.urdf
./build/tools/kinograph info robots/acrobot/acrobot.urdf
