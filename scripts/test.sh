#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs every test.
# LCM multicast tests need a multicast route; as root the whole suite runs inside a private
# network namespace whose loopback carries 224.0.0.0/4, so no packet leaves this machine.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
BUILD_DIR=${KINOGRAPH_BUILD_DIR:-build}
CTEST="ctest --test-dir $BUILD_DIR --output-on-failure -j $(nproc) --timeout 600"
if [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null; then
  exec unshare -n sh -c "ip link set lo up && ip link set lo multicast on && \
    ip route add 224.0.0.0/4 dev lo && $CTEST"
else
  echo "test.sh: not root, running without a private network namespace (LCM tests use memq://)"
  exec $CTEST
fi
