#!/usr/bin/env bash
# The microcontroller firmware (board/, issue 36) in QEMU's netduinoplus2 (STM32F405) on the host:
# virtual time (-icount shift=0,sleep=off: one instruction a nanosecond, idle time skipped).
#  1. The default square: every pose frame the firmware sends over SLCAN (USART1) equals, byte
#     for byte, odometryd --virtual-time's for the same scenario (its --can-log), the final
#     pose included; no missed deadline, no dropped frame; odomctl decode reads the firmware's
#     frames (converted to candump -L).
#  2. Set-pose over SLCAN: decoded with protocol/, posted to the loop; the next pose frames start
#     from it and the status frame acknowledges it.
#     USART2 carries the serial counts stream (issue 37) at 100 Hz, checked record by record.
#  3. A bus fault: the fault handler reports the registers on USART1 and QEMU exits with 3.
#  4. Calibrated from a flash image (-device loader at sector 10): equal to odometryd with the
#     same store file; without the image the firmware runs uncalibrated.
#  5. At 1 kHz with the covariance merged ten ticks at a time (--rate-hz 1000 --covariance-ticks
#     10): pose frames equal odometryd's with the same [loop] and [error_model], no missed deadline.
#  6. Two wheels per side (the image MCU_ELF's name + _w2, issue 38): in virtual time its pose
#     frames equal odometryd --virtual-time's with [encoder] wheels_per_side = 2 (the same
#     simulated wheels, combined on the board) and USART2 carries version 2 records, two counters a
#     side; then paced at real time, USART2 on a pty, odometryd's serial backend with
#     wheels_per_side = 2 reads those records and combines each side itself: its final pose
#     equals the board's final pose frame.
# usage: test_mcu_qemu.sh SOURCE_DIR MCU_ELF   (env ODOMETRYD, ODOMCTL)
set -u
src=$1
elf=$2
. "$src/tests/cli/lib.sh"  # check, $tmp
tool="$src/tests/mcu/slcan_tool.py"
qemu() {  # qemu OUT ARGS...: the firmware with USART1 into OUT; its exit code
  local out=$1
  shift
  local args=arg=odo
  for a in "$@"; do args="$args,arg=$a"; done
  timeout 300 qemu-system-arm -M netduinoplus2 -display none -monitor none \
    -serial "file:$out" -serial "file:$out.usart2" -kernel "$elf" -icount shift=0,sleep=off \
    -semihosting-config "enable=on,target=native,$args"
}

# 1. The default square against odometryd.
qemu "$tmp/usart1.txt"
check "firmware exits 0 after the square" $?
tr '\r' '\n' <"$tmp/usart1.txt" | grep '^# end' >"$tmp/end"
check "firmware's final report" $?
grep -q ' missed=0 ' "$tmp/end" && grep -q ' dropped=0 ' "$tmp/end"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "no missed deadline, no dropped frame: $(cat "$tmp/end")" $rc
"$ODOMETRYD" --virtual-time --can-log "$tmp/host.log" >/dev/null 2>"$tmp/host.err"
check "odometryd --virtual-time exit 0" $?
python3 "$tool" candump "$tmp/usart1.txt" "$tmp/mcu.log"
pose() { grep -E ' (410|411)#' "$1" | sed 's/.* //'; }
# frames_equal_unlike_default CAPTURE TAG: the firmware's pose frames in its USART1 CAPTURE
# ($tmp/mcuTAG.log as candump -L) equal odometryd's in $tmp/hostTAG.log and differ from the
# default run's ($tmp/host.pose).
frames_equal_unlike_default() {
  python3 "$tool" candump "$1" "$tmp/mcu$2.log"
  pose "$tmp/host$2.log" >"$tmp/host$2.pose"
  pose "$tmp/mcu$2.log" >"$tmp/mcu$2.pose"
  [ -s "$tmp/host$2.pose" ] && cmp -s "$tmp/host$2.pose" "$tmp/mcu$2.pose" &&
    ! cmp -s "$tmp/host$2.pose" "$tmp/host.pose"
}
pose "$tmp/host.log" >"$tmp/host.pose"
pose "$tmp/mcu.log" >"$tmp/mcu.pose"
[ -s "$tmp/host.pose" ] && cmp -s "$tmp/host.pose" "$tmp/mcu.pose"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "all $(wc -l <"$tmp/host.pose") pose frames bit-identical to odometryd's" $rc
[ "$(tail -2 "$tmp/host.pose")" = "$(tail -2 "$tmp/mcu.pose")" ]
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "final broadcast pose identical: $(tail -2 "$tmp/mcu.pose" | tr '\n' ' ')" $rc
"$ODOMCTL" decode "$tmp/mcu.log" >"$tmp/decoded" 2>&1 && grep -q ' PoseYTheta .*theta=' "$tmp/decoded"
check "odomctl decode reads the firmware's frames" $?
# The stopping status (last frame): its stopping flag set, as odometryd's.
[ "$(tail -1 "$tmp/mcu.log" | sed 's/.* //')" = "$(tail -1 "$tmp/host.log" | sed 's/.* //')" ] ||
  "$ODOMCTL" decode --csv "$tmp/mcu.log" | grep -q 'Status,stopping,1'
check "stopping status frame" $?

# USART2: the serial counts stream (issue 37's format, decoded from its spec by slcan_tool.py):
# one record a tick at the default 100 Hz, the first flagged 'booted', seq +1 and time +10 ms;
# version 1 (one wheel per side: what every host reads).
read -r n f0 fmax seq_ok dts ver wps _ <<<"$(python3 "$tool" serial "$tmp/usart1.txt.usart2")"
ticks=$(sed -E 's/.* ticks=([0-9]+) .*/\1/' "$tmp/end")
[ "$n" = "$ticks" ] && [ "$f0" = 4 ] && [ "$fmax" = 0 ] && [ "$seq_ok" = 1 ] && [ "$dts" = "[10000]" ] && [ "$ver" = 1 ] && [ "$wps" = 1 ]
check "serial counts on USART2: $n version $ver records of $ticks ticks, CRC and COBS valid, seq and 10 ms steps" $?

# 2. Set-pose (10 m, 20 m, 1 rad) after 100 pose frames.
python3 "$tool" setpose "$elf" 10 20 1 >"$tmp/after.log" 2>"$tmp/after.err"
check "firmware with set-pose exits 0" $?
"$ODOMCTL" decode --csv "$tmp/after.log" >"$tmp/after.csv"
python3 - "$tmp/after.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
groups, x = [], None  # (x, y) of each pose group: a PoseX, then its PoseYTheta
for r in rows:
    if r[4] == "PoseX" and r[5] == "x":
        x = float(r[6])
    elif r[4] == "PoseYTheta" and r[5] == "y" and x is not None:
        groups.append((x, float(r[6])))
ack = [float(r[6]) for r in rows if r[4] == "Status" and r[5] == "set_pose_ack"]
gx, gy = next(g for g in groups if g[0] > 5)  # the first pose group after the command
# The robot moves at most 0.2 m/s: within 2 ticks (20 ms) of the set pose, 4 mm.
assert abs(gx - 10) < 0.005 and abs(gy - 20) < 0.005, (gx, gy)
assert ack and ack[-1] == 1, ack
PY
check "set-pose over SLCAN: next pose frames start at (10, 20), status acknowledges" $?
grep -q ' set_pose=1 ' "$tmp/after.err"
check "firmware counted one set-pose" $?

# 4. Calibrated from flash: a store written by odomctl calib set, its slot A placed at flash
# sector 10 (0x080C0000, -device loader; the rest of sectors 10-11 erased, 0xFF): the firmware
# reports the record and its pose frames equal odometryd's with the same store file.
"$ODOMCTL" calib set --store "$tmp/cal.bin" --cl 0.998 --cr 1.002 --wheelbase 0.337 >/dev/null
check "odomctl calib set" $?
python3 - "$tmp/cal.bin" "$tmp/calimg.bin" <<'PY'
import sys
d = open(sys.argv[1], "rb").read()
n = int.from_bytes(d[6:8], "little")  # the record's length field (slot A starts the file)
img = bytearray(b"\xff" * (2 * 128 * 1024))
img[:n] = d[:n]
open(sys.argv[2], "wb").write(img)
PY
sed "s|^store = .*|store = \"$tmp/cal.bin\"|" "$src/firmware/config/odometryd.toml" >"$tmp/cal.toml"
"$ODOMETRYD" --config "$tmp/cal.toml" --virtual-time --can-log "$tmp/hostcal.log" >"$tmp/hostcal.err" 2>&1
check "odometryd with the store exit 0" $?
grep -q 'calibration.*ok, sequence 1' "$tmp/hostcal.err"
check "odometryd runs calibrated" $?
timeout 300 qemu-system-arm -M netduinoplus2 -display none -monitor none \
  -serial "file:$tmp/cal.txt" -serial null -kernel "$elf" -icount shift=0,sleep=off \
  -device "loader,file=$tmp/calimg.bin,addr=0x080C0000" \
  -semihosting-config enable=on,target=native,arg=odo
check "calibrated firmware exits 0" $?
tr '\r' '\n' <"$tmp/cal.txt" | grep -q '^# calibration (flash sectors 10-11): ok, sequence 1'
check "firmware loads the record from flash" $?
frames_equal_unlike_default "$tmp/cal.txt" cal
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "calibrated: $(wc -l <"$tmp/mcucal.pose") pose frames equal odometryd's, unlike the uncalibrated run" $rc
"$ODOMCTL" decode --csv "$tmp/mcucal.log" | grep 'Status,calibration_state,' | tail -1 | grep -q ',1$'
check "Status says calibrated" $?
tr '\r' '\n' <"$tmp/usart1.txt" | grep -q '^# calibration (flash sectors 10-11): uncalibrated'
check "without the image: uncalibrated" $?

# 5. 1 kHz, covariance every 10 ticks: the same pose frames as odometryd configured alike.
sed -e '0,/^rate_hz = .*/s//rate_hz = 1000/' -e 's|^covariance_ticks = .*|covariance_ticks = 10|' \
  "$src/firmware/config/odometryd.toml" >"$tmp/khz.toml"
grep -q '^rate_hz = 1000' "$tmp/khz.toml" && grep -q '^covariance_ticks = 10' "$tmp/khz.toml"
check "1 kHz config written" $?
"$ODOMETRYD" --config "$tmp/khz.toml" --virtual-time --can-log "$tmp/hostkhz.log" >/dev/null 2>&1
check "odometryd at 1 kHz exit 0" $?
qemu "$tmp/khz.txt" --rate-hz 1000 --covariance-ticks 10
check "firmware at 1 kHz exits 0" $?
tr '\r' '\n' <"$tmp/khz.txt" | grep '^# end' >"$tmp/khz.end"
grep -q '^# end ticks=97566 missed=0 ' "$tmp/khz.end"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "1 kHz: ten times the ticks, none missed: $(cat "$tmp/khz.end")" $rc
python3 "$tool" candump "$tmp/khz.txt" "$tmp/mcukhz.log"
pose "$tmp/hostkhz.log" >"$tmp/hostkhz.pose"
pose "$tmp/mcukhz.log" >"$tmp/mcukhz.pose"
# (They also equal the 100 Hz run's: the signals' resolution, 0.1 mm and 1e-4 rad, hides the
# sub-micrometre difference the sampling rate makes on this path.)
[ -s "$tmp/hostkhz.pose" ] && cmp -s "$tmp/hostkhz.pose" "$tmp/mcukhz.pose"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "1 kHz: $(wc -l <"$tmp/mcukhz.pose") pose frames equal odometryd's" $rc

qemu "$tmp/khzbad.txt" --covariance-ticks 0 --duration 1
[ $? = 2 ] && tr '\r' '\n' <"$tmp/khzbad.txt" |
  grep -q '^# error: error_model.covariance_ticks = 0 is outside the allowed range \[1, 100\]'
check "--covariance-ticks 0 refused (exit 2) naming the setting and its range" $?

# 6. Two wheels per side.
elf2=${elf%.elf}_w2.elf
sed 's/^wheels_per_side = 1 /wheels_per_side = 2 /' "$src/firmware/config/odometryd.toml" >"$tmp/w2.toml"
grep -q '^wheels_per_side = 2 ' "$tmp/w2.toml"
check "two-wheel config written" $?
"$ODOMETRYD" --config "$tmp/w2.toml" --virtual-time --can-log "$tmp/hostw2.log" >/dev/null 2>&1
check "odometryd --virtual-time with two wheels per side exit 0" $?
elf_one=$elf
elf=$elf2 qemu "$tmp/w2.txt"
check "two-wheel firmware exits 0 after the square" $?
elf=$elf_one
tr '\r' '\n' <"$tmp/w2.txt" | grep '^# end' >"$tmp/w2.end"
grep -q ' missed=0 ' "$tmp/w2.end" && grep -q ' dropped=0 ' "$tmp/w2.end"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "two wheels: no missed deadline, no dropped frame: $(cat "$tmp/w2.end")" $rc
frames_equal_unlike_default "$tmp/w2.txt" w2
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "two wheels: $(wc -l <"$tmp/mcuw2.pose") pose frames equal odometryd's with wheels_per_side = 2, unlike one wheel's" $rc
# Its SideWheels frames (0x417: slip and dropped-wheel flags, wheels per side, counters) are
# odometryd's, one before each Status; the one-wheel image sends none.
grep -o ' 417#[0-9A-F]*$' "$tmp/hostw2.log" >"$tmp/hostw2.side"
grep -o ' 417#[0-9A-F]*$' "$tmp/mcuw2.log" >"$tmp/mcuw2.side"
[ -s "$tmp/mcuw2.side" ] && cmp -s "$tmp/hostw2.side" "$tmp/mcuw2.side" &&
  [ "$(wc -l <"$tmp/mcuw2.side")" = "$(grep -c ' 414#' "$tmp/mcuw2.log")" ] &&
  ! grep -q ' 417#' "$tmp/mcu.log"
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "two wheels: $(wc -l <"$tmp/mcuw2.side") SideWheels frames equal odometryd's, one per Status; none from one wheel's image" $rc
read -r n f0 fmax seq_ok dts ver wps faults lefts rights <<<"$(python3 "$tool" serial "$tmp/w2.txt.usart2")"
ticks=$(sed -E 's/.* ticks=([0-9]+) .*/\1/' "$tmp/w2.end")
# The two wheels of a side differ by their radii (sim_hal's 0.3 % tolerance), never by more than
# 1 % over the square.
python3 - "$lefts" "$rights" <<'PY'
import sys
for side in sys.argv[1:]:
    a, b = (int(v) for v in side.split(","))
    assert a != b and abs(a - b) < 0.01 * max(abs(a), abs(b)), side
PY
rc=$?
[ $rc = 0 ] && [ "$n" = "$ticks" ] && [ "$f0" = 4 ] && [ "$fmax" = 0 ] && [ "$seq_ok" = 1 ] &&
  [ "$dts" = "[10000]" ] && [ "$ver" = 2 ] && [ "$wps" = 2 ] && [ "$faults" = 0 ]
check "two wheels: $n version $ver records, $wps counters a side (last: left $lefts, right $rights), no wheel fault" $?
# The daemon on the serial line: the firmware's USART2 bytes of a 24 s run (the first side, the
# turn, ending in the pause after it) on a pty at the records' own pace, 10 ms apart, and
# odometryd's serial backend with wheels_per_side = 2 reading them and combining each side
# itself. (Not QEMU paced at real time onto the pty: on a loaded machine QEMU falls behind in
# bursts, the host maps the controller's clock onto its own from arrival times, and a burst
# after a stall of over 100 ms read as stale and as implausible jumps, seen on this two-core
# machine.)
elf=$elf2 qemu "$tmp/w2rt.txt" --duration 24
check "two-wheel firmware, 24 s, exits 0" $?
serial_config diffodom "$tmp/u2w2" 115200
# Two wheels per side; a store and a state file of its own (part 4's store is calibrated).
sed -i -e 's/^backend = "serial"$/backend = "serial"\nwheels_per_side = 2/' \
  -e 's|/cal.bin"$|/w2cal.bin"|' -e 's|/state.bin"$|/w2state.bin"|' "$tmp/serial.toml"
python3 "$tool" pace "$tmp/w2rt.txt.usart2" "$tmp/u2w2" 2.0 2>"$tmp/pace.err" &
ppid=$!
poll 5 test -e "$tmp/u2w2"
"$ODOMETRYD" --config "$tmp/serial.toml" --json --quiet >"$tmp/w2rt.json" 2>"$tmp/w2rt.err" &
opid=$!
wait "$ppid"
check "the firmware's records written to the pty: $(cat "$tmp/pace.err")" $?
kill -TERM "$opid"
wait "$opid"
check "odometryd on the serial line (two wheels per side) exit 0 after SIGTERM" $?
python3 "$tool" candump "$tmp/w2rt.txt" "$tmp/w2rt.log"
"$ODOMCTL" decode --csv "$tmp/w2rt.log" >"$tmp/w2rt.csv"
python3 - "$tmp/w2rt.json" "$tmp/w2rt.csv" "$tmp/w2rt.txt.usart2" "$src/tests/mcu" <<'PY'
import csv, json, math, sys
sys.path.insert(0, sys.argv[4])
import slcan_tool
d = json.load(open(sys.argv[1]))
rows = list(csv.reader(open(sys.argv[2])))
# odometryd's pose starts at the first record it reads (10 ms after the board's reference at
# boot): the board's first 10 ms, straight ahead along x, are not in it. That record's travel:
# the mean of its four counters (from 0 at boot) times pi 0.15 m / (2048 * 16) a count.
first = slcan_tool.serial_records(sys.argv[3])[0]
d0 = (sum(first[4]) + sum(first[5])) / 4 * math.pi * 0.15 / (2048 * 16)
x = [float(r[6]) for r in rows if r[4] == "PoseX" and r[5] == "x"][-1]
y = [float(r[6]) for r in rows if r[4] == "PoseYTheta" and r[5] == "y"][-1]
th = [float(r[6]) for r in rows if r[4] == "PoseYTheta" and r[5] == "theta"][-1]
print("odometryd", {k: d[k] for k in ("x", "y", "theta", "link_errors", "sequence_gaps",
      "implausible_jumps")}, d.get("wheels"), "board", (x, y, th), "first record", d0)
# The board's frames carry 0.1 mm and 1e-4 rad; the robot drove 4 m and turned 90 degrees.
assert d["x"] > 3.9 and abs(d["x"] + d0 - x) <= 2e-4 and abs(d["y"] - y) <= 2e-4, (d, d0, x, y)
assert abs(math.remainder(d["theta"] - th, 2 * math.pi)) <= 2e-4 and th > 1.5, (d, th)
assert d["wheels"]["wheels_per_side"] == 2 and d["wheels"]["wheel_drops"] == 0, d
assert d["wheels"]["slip_events"] == 0 and d["link_errors"] == 0, d
assert d["sequence_gaps"] == 0 and d["implausible_jumps"] == 0, d
PY
check "odometryd combining the board's version 2 records per side: final pose equals the board's (less its first 10 ms)" $?

# 3. Fault report.
qemu "$tmp/fault.txt" --fault
[ $? = 3 ]
check "bus fault: exit code 3" $?
tr '\r' '\n' <"$tmp/fault.txt" | grep -E '^# FAULT exc=0x00000003 .* pc=0x0800[0-9A-F]{4} .*cfsr=0x0000..00 hfsr=0x40000000' >/dev/null
rc=$?  # before the name is expanded: its $(...) would set $? to its own status
check "fault handler prints the registers ($(tr '\r' '\n' <"$tmp/fault.txt" | grep FAULT | cut -c1-60)...)" $rc

echo "test_mcu_qemu: $pass passed, $fail failed"
[ "$fail" = 0 ]
