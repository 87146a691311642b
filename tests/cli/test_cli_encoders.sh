#!/usr/bin/env bash
# odometryd with the encoder backends of issue 5 on this (non-VM) machine: the HCTL-1100
# driver over the register model runs the whole square; hardware backends that cannot open
# their GPIO chip fail with exit 2 and a message naming the file, section and chip.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget

# Same square through the simulated backend and through HCTL-1100 models + driver: the poses
# agree to a fraction of a millimetre (the chips are read a few bus cycles later).
for latch in none lsb; do
  printf '[encoder]\nbackend = "hctl1100"\n[hctl1100]\nbus = "sim"\nlatch = "%s"\nbus_cycle = 2e-6\n' \
    "$latch" >"$tmp/h.toml"
  run "$ODOMETRYD" --config "$tmp/h.toml" --virtual-time --json >"$tmp/h.json" 2>"$tmp/err"
  check "hctl1100 sim ($latch) exit 0" $?
  run "$ODOMETRYD" --virtual-time --json >"$tmp/s.json" 2>/dev/null
  python3 - "$tmp/h.json" "$tmp/s.json" <<'PY'
import json, sys
h = json.load(open(sys.argv[1])); s = json.load(open(sys.argv[2]))
assert h["ticks"] == s["ticks"], (h, s)
assert abs(h["x"] - s["x"]) < 5e-4 and abs(h["y"] - s["y"]) < 5e-4, (h, s)
assert abs(h["distance"] - s["distance"]) < 5e-3, (h, s)
for k in ("implausible_jumps", "invalid_transitions", "read_errors"):
    assert h[k] == 0, (k, h)
PY
  check "hctl1100 sim ($latch) matches the sim backend" $?
done

printf '[encoder]\nbackend = "gpio"\n[gpio]\nchip = "/dev/gpiochip-none"\n' >"$tmp/g.toml"
run "$ODOMETRYD" --config "$tmp/g.toml" --duration 1 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "gpio without chip exit 2 (got $rc)" $?
grep -q "g.toml: \[gpio\] GPIO chip '/dev/gpiochip-none' cannot be opened" "$tmp/err"
check "gpio without chip: file, section and chip named" $?

printf '[encoder]\nbackend = "hctl1100"\n[hctl1100]\nchip = "/dev/gpiochip-none"\n' >"$tmp/b.toml"
run "$ODOMETRYD" --config "$tmp/b.toml" --duration 1 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "hctl1100 gpio bus without chip exit 2 (got $rc)" $?
grep -q "b.toml: \[hctl1100\] GPIO chip '/dev/gpiochip-none'" "$tmp/err"
check "hctl1100 without chip: named" $?

run "$ODOMETRYD" --config "$tmp/g.toml" --virtual-time >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "gpio with --virtual-time exit 2 (got $rc)" $?

# CAN counts (backend 3) from two simulated ODrive axes publishing every 10 ms, read by the real
# driver: the same square as the simulated backend, tick for tick (the axes publish at the
# loop's 10 ms tick times, so every read sees the counts of that very instant).
printf '[encoder]\nbackend = "can"\n[can_encoder]\nbus = "sim"\nnode_left = 3\nnode_right = 7\n' \
  >"$tmp/c.toml"
run "$ODOMETRYD" --config "$tmp/c.toml" --virtual-time --json >"$tmp/c.json" 2>"$tmp/err"
check "can sim exit 0" $?
# $tmp/s.json: the simulated backend's run from the HCTL-1100 comparison above.
python3 - "$tmp/c.json" "$tmp/s.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1])); s = json.load(open(sys.argv[2]))
assert c["ticks"] == s["ticks"], (c, s)
assert abs(c["x"] - s["x"]) < 1e-9 and abs(c["y"] - s["y"]) < 1e-9, (c, s)
assert c["encoder_flags"] == 0 and c["stale_events"] == 0 and c["implausible_jumps"] == 0, c
PY
check "can sim matches the sim backend" $?
grep -q "ODrive CAN Simple encoder counts (nodes 3/7, left id 0x6A" "$tmp/err"
check "can sim: start-up report names nodes and ids (3 << 5 | 0xA = 0x6A)" $?

# A stopped sender: the left axis stops publishing after 1 s; real time, status lines every
# 0.5 s. Stale is flagged 0.1 s (the timeout) after the last frame, so the status lines at
# 1.5 s and 2 s say stale-left and count one stale event; the line at 0.5 s says ok.
printf '[loop]\nstatus_period = 0.5\n[realtime]\npriority = 0\nlock_memory = false\n[encoder]\nbackend = "can"\n[can_encoder]\nbus = "sim"\nsim_stop_left_after = 1.0\n' \
  >"$tmp/stop.toml"
run "$ODOMETRYD" --config "$tmp/stop.toml" --duration 2.3 --json >"$tmp/stop.json" 2>"$tmp/stop.err"
check "can sim stopped sender exit 0" $?
grep "^t=" "$tmp/stop.err" | head -1 | grep -q "enc=ok"
check "can sim: ok before the sender stops" $?
grep "^t=" "$tmp/stop.err" | tail -1 | grep -q "enc=stale-left (invalid=0 jumps=0 stale=1 read_errors=0)"
check "can sim: stale-left with stale=1 in the status line after the sender stopped" $?
python3 - "$tmp/stop.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert j["encoder_flags"] == 1 and j["stale_events"] == 1, j  # kEncoderStaleLeft = 1
PY
check "can sim: --json carries the stale flag and one stale event" $?

printf '[encoder]\nbackend = "can"\n[can_encoder]\ninterface = "nocan7"\n' >"$tmp/n.toml"
run "$ODOMETRYD" --config "$tmp/n.toml" --duration 1 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "can without interface exit 2 (got $rc)" $?
grep -q "n.toml: \[can_encoder\] .*nocan7" "$tmp/err"
check "can without interface: file, section and interface named" $?

echo "cli encoders: $pass passed, $fail failed"
[ $fail = 0 ]
