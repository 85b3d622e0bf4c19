# Sourced by the udpm tests: re-runs the calling script in a private network namespace with a
# loopback multicast route, so nothing it sends leaves the namespace. Exit 77 (skipped) when
# not root. Must be sourced before the script does anything else with "$@".
if [ -z "${KINOGRAPH_NETNS:-}" ]; then
  if [ "$(id -u)" -ne 0 ] || ! command -v unshare >/dev/null; then
    echo "SKIP: needs root for a private network namespace"; exit 77
  fi
  exec unshare -n env KINOGRAPH_NETNS=1 bash "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo
