#!/usr/bin/env bash
# The shipped systemd unit passes `systemd-analyze verify` (with ExecStart pointed at the built
# binary, since /usr/bin/odometryd exists only once installed). Exit 77 (skipped) without
# systemd-analyze.
# With a second argument, a drop-in (ros2/systemd/ros2.conf: the ROS 2 output on): the unit
# plus the drop-in pass verify too, and `systemd-analyze security` rates them no worse than the
# unit alone (the drop-in opens UDP for DDS and must pay for it elsewhere).
set -u
unit=$1
dropin=${2:-}
command -v systemd-analyze >/dev/null || { echo "SKIPPED: systemd-analyze not installed (apt-get install systemd)"; exit 77; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
grep -q '^ExecStart=/usr/bin/odometryd ' "$unit" || { echo "FAIL: ExecStart is not /usr/bin/odometryd"; exit 1; }
sed "s|^ExecStart=/usr/bin/odometryd |ExecStart=$ODOMETRYD |" "$unit" >"$tmp/odometryd.service"
# --man=no: the unit's Documentation= names man pages, and whether `man` is installed (it is not
# on a minimal Debian) says nothing about the unit.
out=$(systemd-analyze verify --man=no "$tmp/odometryd.service" 2>&1); rc=$?
[ -z "$out" ] || echo "$out"
[ $rc = 0 ] && [ -z "$out" ] || { echo "FAIL: systemd-analyze verify"; exit 1; }
for key in Type=notify WatchdogSec= 'AmbientCapabilities=CAP_SYS_NICE CAP_IPC_LOCK' \
  'CapabilityBoundingSet=CAP_SYS_NICE CAP_IPC_LOCK' NoNewPrivileges=yes \
  RuntimeDirectory=odometryd RuntimeDirectoryPreserve=restart 'Environment=ODOMETRYD_BOOT_ID=%b'; do
  grep -q "^$key" "$unit" || { echo "FAIL: $key missing"; exit 1; }
done
echo "systemd unit: verify clean"
[ -n "$dropin" ] || exit 0

# exposure DIR: the overall exposure level systemd-analyze security gives DIR/odometryd.service
# (with the drop-ins beside it, in odometryd.service.d/).
exposure() {
  systemd-analyze security --offline=true "$1/odometryd.service" 2>/dev/null |
    sed -n 's/.*Overall exposure level for odometryd.service: \([0-9.]*\).*/\1/p'
}
mkdir -p "$tmp/on/odometryd.service.d"
cp "$tmp/odometryd.service" "$tmp/on/"
cp "$dropin" "$tmp/on/odometryd.service.d/ros2.conf"
out=$(systemd-analyze verify --man=no "$tmp/on/odometryd.service" 2>&1); rc=$?
[ -z "$out" ] || echo "$out"
[ $rc = 0 ] && [ -z "$out" ] || { echo "FAIL: systemd-analyze verify with the drop-in"; exit 1; }
# What DDS needs, and that the unit's IP deny stays the default.
for key in 'RestrictAddressFamilies=AF_UNIX AF_INET AF_INET6 AF_NETLINK' SocketBindAllow=udp \
  SocketBindDeny=any; do
  grep -q "^$key" "$dropin" || { echo "FAIL: drop-in: $key missing"; exit 1; }
done
grep -q '^IPAddressDeny=any' "$unit" || { echo "FAIL: the unit lost IPAddressDeny=any"; exit 1; }
base=$(exposure "$tmp"); on=$(exposure "$tmp/on")
[ -n "$base" ] && [ -n "$on" ] || { echo "FAIL: no exposure level from systemd-analyze security"; exit 1; }
echo "systemd-analyze security: unit $base, unit + ros2 drop-in $on"
awk -v a="$on" -v b="$base" 'BEGIN { exit !(a <= b) }' ||
  { echo "FAIL: the drop-in makes the unit less hardened ($on > $base)"; exit 1; }
echo "systemd unit with the ROS 2 drop-in: verify clean, exposure not worse"
