#!/usr/bin/env bash
# odometryd with the encoder backends of issue 5 on this (non-VM) machine: the HCTL-1100
# driver over the register model runs the whole square; hardware backends that cannot open
# their GPIO chip fail with exit 2 and a message naming the file, section and chip.
set -u
run() { ${CROSS_EMULATOR:-} "$@"; }
fail=0; pass=0
check() {  # check NAME CONDITION-RESULT
  if [ "$2" = 0 ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $1"; fi
}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

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

echo "cli encoders: $pass passed, $fail failed"
[ $fail = 0 ]
