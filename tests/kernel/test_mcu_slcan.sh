#!/usr/bin/env bash
# Kernel tier (in the VM, tools/vm-run.sh): the microcontroller firmware's USART1 as a real
# SocketCAN interface. qemu-system-arm runs board/'s QEMU image inside the VM (the VM shares the
# host's root, so the host's QEMU is there) with USART1 on a pty; slcand (can-utils) attaches the
# kernel's slcan line discipline to it, giving slcan0. The firmware's frames are captured with
# candump -L on slcan0 and decoded with odomctl decode (the project's DBC layout); a set-pose
# sent with cansend comes back in the next pose frames and in Status's acknowledgement.
# Why QEMU inside the VM and not a host QEMU's chardev into it: one process tree, one pty, no
# socket plumbing through the VM's 9p share; the firmware needs ~2 M instructions a second.
# usage: test_mcu_slcan.sh MCU_ELF   (env ODOMCTL); exit 77 when the image is not built (not CI)
set -u
elf=$1
. "$(dirname "$0")/../cli/lib.sh"  # check, $tmp
if [ ! -f "$elf" ]; then
  echo "SKIPPED: $elf not built (cmake --build --preset mcu-stm32f405)"
  [ "${CI:-}" = true ] && exit 1
  exit 77
fi
if ! modprobe slcan 2>/dev/null; then
  # Outside the VM (our machines' kernel has no CAN): as every kernel-tier test, skipped there.
  echo "SKIPPED: no slcan module here (the kernel tier runs in tools/vm-run.sh)"
  [ "${CI:-}" = true ] && [ -n "${ODO_IN_VM:-}" ] && exit 1
  exit 77
fi
qemu-system-arm -M netduinoplus2 -display none -monitor none -serial pty -kernel "$elf" \
  -icount shift=0 -semihosting-config enable=on,target=native,arg=odo,arg=--duration,arg=0 \
  >"$tmp/qemu.out" 2>&1 &
qpid=$!
trap 'kill $qpid $spid $cpid 2>/dev/null; rm -rf "$tmp"' EXIT
spid= cpid=
poll 30 grep -q 'redirected to /dev/pts/' "$tmp/qemu.out"
check "QEMU's USART1 on a pty" $?
pty=$(sed -nE 's|.*redirected to (/dev/pts/[0-9]+).*|\1|p' "$tmp/qemu.out" | head -1)
slcand -o -c -s6 -F "$pty" slcan0 &
spid=$!
poll 20 ip link show slcan0 >/dev/null 2>&1
check "slcand made slcan0 from $pty" $?
ip link set slcan0 up
candump -L slcan0 >"$tmp/can.log" &
cpid=$!
poll 60 grep -q ' 411#' "$tmp/can.log"
check "pose frames arrive on slcan0" $?
# set-pose: x 10 m, y 20 m (int24 mm), theta 1 rad (int16 1e-4 rad), to node 1 (0x400+16+8).
cansend slcan0 418#102700204E001027
check "cansend set-pose" $?
poll 60 bash -c "\"$ODOMCTL\" decode --csv \"$tmp/can.log\" | grep -q 'Status,set_pose_ack,1\$'"
check "Status acknowledges the set-pose" $?
sleep 1
kill $cpid 2>/dev/null
wait $cpid 2>/dev/null
"$ODOMCTL" decode --csv "$tmp/can.log" >"$tmp/can.csv"
check "odomctl decode reads slcan0's capture" $?
python3 - "$tmp/can.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
groups, x = [], None
for r in rows[1:]:
    if r[4] == "PoseX" and r[5] == "x":
        x = float(r[6])
    elif r[4] == "PoseYTheta" and r[5] == "y" and x is not None:
        groups.append((x, float(r[6])))
before = [g for g in groups if g[0] < 5]
after = [g for g in groups if g[0] > 5]
assert before and after, (len(before), len(after))
# The robot moves at most 0.2 m/s; the first group after the command is within 5 mm of (10, 20)
# and every later one within the distance driven since.
assert abs(after[0][0] - 10) < 0.005 and abs(after[0][1] - 20) < 0.005, after[0]
print(f"{len(groups)} pose groups on slcan0, first after set-pose {after[0]}")
PY
check "pose frames after the set-pose start at (10, 20)" $?
echo "test_mcu_slcan: $pass passed, $fail failed"
[ "$fail" = 0 ]
