#!/usr/bin/env bash
# The Python client (share/kinograph/python) against the real kinographd over UDP multicast in
# a private network namespace (nothing leaves it): daemon_client_test.py sends the goals.
# Usage: daemon_client_test.sh BUILD_DIR SOURCE_DIR PYTHON PYTHON_DIR. Exit 77 (skipped) when
# not root.
set -euo pipefail
BUILD=$1
SRC=$2
PYTHON=$3
PYTHON_DIR=$4
source "$SRC/tests/daemon/udpm_lib.sh"
URL="udpm://239.255.76.67:7721?ttl=0&recv_buf_size=4194304"

start_daemon "$SRC/robots/scenes/rr_reach.yaml" "$URL" "$WORK/daemon.log"
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$PYTHON_DIR" "$PYTHON" \
  "$SRC/tests/python/daemon_client_test.py" "$URL" RR "$SRC/robots/rr/rr.urdf" \
  || fail "the Python client's goals were not answered as expected"
