# Sourced first by the LCM demos (scripts/*_demo.sh): as root, re-runs the calling script in a
# private network namespace whose loopback carries the multicast group, so no packet leaves this
# machine; otherwise the script goes on with ttl=0 URLs (packets stay on this host).
if [ -z "${KINOGRAPH_NETNS:-}" ] && [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null; then
  exec unshare -n env KINOGRAPH_NETNS=1 bash "$0" "$@"
fi
if [ -n "${KINOGRAPH_NETNS:-}" ]; then
  ip link set lo up
  ip link set lo multicast on
  ip route add 224.0.0.0/4 dev lo
fi
