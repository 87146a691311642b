#!/usr/bin/env bash
# odomctl calib show|set|import|export|reset on a file store, and odometryd reading the store
# at start and on SIGHUP: exit codes, JSON, range checks that leave the store untouched.
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget
S=(--store "$tmp/cal.bin")

# Never written: uncalibrated, exit 0, factors 1, no geometry.
run "$ODOMCTL" calib show "${S[@]}" --json >"$tmp/out" 2>"$tmp/err"
check "show blank exit 0" $?
[ "$(jget "$tmp/out" status)" = uncalibrated ]; check "show blank status" $?
[ "$(jget "$tmp/out" wheelbase)" = None ]; check "show blank wheelbase null" $?
[ ! -e "$tmp/cal.bin" ]; check "show does not create the store" $?

# odometryd at boot on a store that was never written (no file): runs on nominal values,
# calibration_state 0, says so, creates nothing.
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "%s"\n' "$tmp/cal.bin" >"$tmp/d0.toml"
run "$ODOMETRYD" --config "$tmp/d0.toml" --virtual-time --duration 1 --json >"$tmp/out" 2>"$tmp/err"
check "odometryd on a missing store exit 0" $?
[ "$(jget "$tmp/out" calibration_state)" = 0 ] && grep -q "uncalibrated .*running on nominal values" "$tmp/err"
rc_=$?
check "odometryd on a missing store: state 0, nominal: $(grep calibration "$tmp/err")" $rc_
[ ! -e "$tmp/cal.bin" ]; check "odometryd does not create the store" $?
# A store device that is not there: runs on nominal values, state 2 (an error, not "uncalibrated").
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "/dev/mtd99"\n' >"$tmp/dx.toml"
run "$ODOMETRYD" --config "$tmp/dx.toml" --virtual-time --duration 1 --json >"$tmp/out" 2>"$tmp/err"
check "odometryd on a missing store device exit 0" $?
[ "$(jget "$tmp/out" calibration_state)" = 2 ] && grep -q "ERROR: cannot read the store.*NOMINAL" "$tmp/err"
rc_=$?
check "odometryd on a missing store device: state 2: $(grep calibration "$tmp/err")" $rc_

# set: a subset; the rest keep their values.
run "$ODOMCTL" calib set "${S[@]}" --cl 0.998 --wheelbase 0.337 >/dev/null 2>"$tmp/err"
check "set exit 0" $?
run "$ODOMCTL" calib set "${S[@]}" --cr 1.002 --wheel-diameter 0.1502 >/dev/null 2>"$tmp/err"
check "second set exit 0" $?
run "$ODOMCTL" calib show "${S[@]}" --json >"$tmp/out"
python3 - "$tmp/out" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
for k in ("status", "c_l", "c_r", "wheelbase", "wheel_diameter", "sequence"):
    assert k in j, k
assert j["status"] == "ok" and j["sequence"] == 2, j
assert (j["c_l"], j["c_r"], j["wheelbase"], j["wheel_diameter"]) == (0.998, 1.002, 0.337, 0.1502), j
PY
check "show after set" $?

# Rejected values: exit 2, field and range named, store byte-for-byte untouched.
cp "$tmp/cal.bin" "$tmp/before.bin"
for bad in "--cl 1.3:c_l" "--cr nan:c_r" "--wheelbase 0:wheelbase" "--wheel-diameter -0.1:wheel_diameter" \
           "--wheelbase inf:wheelbase"; do
  opt=${bad%%:*}; field=${bad##*:}
  # shellcheck disable=SC2086
  run "$ODOMCTL" calib set "${S[@]}" $opt >"$tmp/out" 2>"$tmp/err"
  rc=$?; [ $rc = 2 ]; check "set $opt exit 2 (got $rc)" $?
  grep -q "$field" "$tmp/err" && grep -q "allowed range" "$tmp/err"
  st=$?; check "set $opt names $field and range: $(cat "$tmp/err")" $st
  cmp -s "$tmp/cal.bin" "$tmp/before.bin"; check "set $opt leaves the store untouched" $?
done
run "$ODOMCTL" calib set "${S[@]}" --cl abc >/dev/null 2>&1
rc=$?; [ $rc = 2 ]; check "set --cl abc exit 2 (got $rc)" $?
run "$ODOMCTL" calib set "${S[@]}" >/dev/null 2>&1
rc=$?; [ $rc = 2 ]; check "set without values exit 2 (got $rc)" $?

# import: the JSON `odomctl umbmark compute --json` prints.
cat >"$tmp/umb.json" <<'J'
{"c_l": 0.99925, "c_r": 1.00075, "b_new": 0.33702, "e_max_syst": 0.232, "n_cw": 5, "n_ccw": 5,
 "alpha": 0.0012, "beta": -0.0004}
J
run "$ODOMCTL" calib import "${S[@]}" "$tmp/umb.json" >/dev/null 2>"$tmp/err"
st=$?; check "import umbmark exit 0 $(cat "$tmp/err")" $st
run "$ODOMCTL" calib export "${S[@]}" >"$tmp/exp.json"
check "export exit 0" $?
[ "$(jget "$tmp/exp.json" wheelbase)" = 0.33702 ] && [ "$(jget "$tmp/exp.json" provenance.runs)" = 10 ] &&
  [ "$(jget "$tmp/exp.json" provenance.method)" = umbmark ]
check "export content" $?
# Round trip through export/import (and stdin).
run "$ODOMCTL" calib import "${S[@]}" - <"$tmp/exp.json" >/dev/null 2>"$tmp/err"
check "import export-format from stdin" $?
run "$ODOMCTL" calib export "${S[@]}" >"$tmp/exp2.json"
python3 - "$tmp/exp.json" "$tmp/exp2.json" <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert a.pop("sequence") + 1 == b.pop("sequence"), (a, b)
assert a == b, (a, b)
PY
check "export/import round trip" $?
# Bad import: exit 2, store untouched.
cp "$tmp/cal.bin" "$tmp/before.bin"
echo '{"c_l": 0.5, "c_r": 1.0}' >"$tmp/bad.json"
run "$ODOMCTL" calib import "${S[@]}" "$tmp/bad.json" >/dev/null 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "import out of range exit 2 (got $rc)" $?
grep -q "bad.json: c_l = 0.5 is outside the allowed range \[0.9, 1.1\]" "$tmp/err"
st=$?; check "import names file, field, range: $(cat "$tmp/err")" $st
echo '{"c_l": 0.99' >"$tmp/trunc.json"
run "$ODOMCTL" calib import "${S[@]}" "$tmp/trunc.json" >/dev/null 2>&1
rc=$?; [ $rc = 2 ]; check "import malformed JSON exit 2 (got $rc)" $?
cmp -s "$tmp/cal.bin" "$tmp/before.bin"; check "bad imports leave the store untouched" $?

# odometryd applies the store and says so; SIGHUP re-reads it.
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "%s"\n' "$tmp/cal.bin" >"$tmp/d.toml"
run "$ODOMETRYD" --config "$tmp/d.toml" --virtual-time --duration 1 --json >"$tmp/out" 2>"$tmp/err"
check "odometryd with store exit 0" $?
[ "$(jget "$tmp/out" calibration_state)" = 1 ]; check "odometryd calibration_state 1" $?
grep -q "calibration $tmp/cal.bin (file): ok, sequence 4: c_l=0.99925" "$tmp/err"
st=$?; check "odometryd reports the store: $(grep calibration "$tmp/err")" $st
if [ -z "${CROSS_EMULATOR:-}" ]; then
  # Waits on the daemon's own lines, not on guessed sleeps (a slow start under the sanitizers
  # must not make the signals land before the handlers, or after the daemon has stopped).
  "$ODOMETRYD" --config "$tmp/d.toml" --duration 60 >"$tmp/live" 2>&1 &
  pid=$!
  wait_text "$tmp/live" "odometryd: loop "
  run "$ODOMCTL" calib set "${S[@]}" --cl 0.997 >/dev/null
  kill -HUP $pid
  wait_text "$tmp/live" "SIGHUP: calibration"
  kill -INT $pid; wait $pid
  check "odometryd survives SIGHUP and stops cleanly" $?
  grep -q "SIGHUP: calibration .*ok, sequence 5: c_l=0.997" "$tmp/live"
  st=$?; check "odometryd re-reads the store on SIGHUP: $(grep SIGHUP "$tmp/live")" $st
fi

# reset: uncalibrated again; export refuses; odometryd runs nominal.
run "$ODOMCTL" calib reset "${S[@]}" >/dev/null
check "reset exit 0" $?
[ "$(run "$ODOMCTL" calib show "${S[@]}" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["status"])')" = uncalibrated ]
check "after reset: uncalibrated" $?
run "$ODOMCTL" calib export "${S[@]}" >/dev/null 2>&1
rc=$?; [ $rc = 1 ]; check "export of uncalibrated exit 1 (got $rc)" $?

# Both slots damaged: corrupt, show exits non-zero, odometryd reports it (state 2).
run "$ODOMCTL" calib set "${S[@]}" --cl 0.999 >/dev/null
printf '\x55' | dd of="$tmp/cal.bin" bs=1 seek=40 conv=notrunc 2>/dev/null
printf '\x55' | dd of="$tmp/cal.bin" bs=1 seek=552 conv=notrunc 2>/dev/null
run "$ODOMCTL" calib show "${S[@]}" --json >"$tmp/out" 2>/dev/null
rc=$?; [ $rc = 1 ]; check "show corrupt exit 1 (got $rc)" $?
[ "$(jget "$tmp/out" status)" = corrupt ] && [ "$(jget "$tmp/out" c_l)" = None ]
check "show corrupt json" $?
run "$ODOMETRYD" --config "$tmp/d.toml" --virtual-time --duration 1 --json >"$tmp/out" 2>"$tmp/err"
[ "$(jget "$tmp/out" calibration_state)" = 2 ] && grep -q "ERROR: store corrupt" "$tmp/err"
check "odometryd reports a corrupt store" $?
run "$ODOMCTL" calib set "${S[@]}" --cl 0.999 >/dev/null 2>&1
rc=$?; [ $rc = 1 ]; check "set on a corrupt store refused (got $rc)" $?
run "$ODOMCTL" calib show --store /dev/mtd99 >/dev/null 2>"$tmp/err"
rc=$?; [ $rc = 1 ] && grep -q "/dev/mtd99" "$tmp/err"; check "missing MTD device named (rc $rc)" $?

echo "calib cli: $pass passed, $fail failed"
[ $fail = 0 ]
