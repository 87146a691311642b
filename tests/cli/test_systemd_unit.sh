#!/usr/bin/env bash
# The shipped systemd unit passes `systemd-analyze verify` (with ExecStart pointed at the built
# binary, since /usr/bin/odometryd exists only once installed). Exit 77 (skipped) without
# systemd-analyze.
set -u
unit=$1
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
  RuntimeDirectory=odometryd RuntimeDirectoryPreserve=restart; do
  grep -q "^$key" "$unit" || { echo "FAIL: $key missing"; exit 1; }
done
echo "systemd unit: verify clean"
