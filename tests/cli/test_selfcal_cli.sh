#!/usr/bin/env bash
# odomctl selfcal simulate --scenario open with --ticks-out/--fixes-out, and calib fit-fixes on
# those files (issue 34): the same estimate as the simulation's own fit; fixes in degrees, a fix
# outside the log's time span and a bad --scenario refused with exit 2; a too-uncertain verdict
# names the bound that failed.
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget
T="$tmp/ticks.csv"; F="$tmp/fixes.csv"

run "$ODOMCTL" selfcal simulate --scenario open --excursions 8 --seed 3 \
  --ticks-out "$T" --fixes-out "$F" >"$tmp/sim.txt" 2>"$tmp/err"
rc_=$?
check "simulate open exit 0 ($(cat "$tmp/err"))" $rc_
[ -s "$T" ] && [ -s "$F" ] && head -1 "$T" | grep -qx "t,left,right" &&
  head -1 "$F" | grep -qx "t,x,y,theta,sigma_xy,sigma_theta"
check "simulate open writes the count log and the fixes" $?
run "$ODOMCTL" selfcal simulate --scenario open --excursions 8 --seed 3 --json >"$tmp/sim.json"
check "simulate open --json exit 0" $?
# The command the simulation prints, as a user would copy it.
fit=$(sed -n 's/^fit them    //p' "$tmp/sim.txt")
[ -n "$fit" ]; check "simulate open prints the fit-fixes command" $?
# shellcheck disable=SC2086
run $ODOMCTL ${fit#odomctl } --json >"$tmp/fit.json" 2>"$tmp/err"
rc_=$?
check "fit-fixes on the simulated files exit 0 ($(cat "$tmp/err"))" $rc_
python3 - "$tmp/sim.json" "$tmp/fit.json" <<'PY'
import json, sys
s, f = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
# Same recorder, same estimator, the files at full precision: the same numbers.
for k in ("c_l", "c_r", "wheelbase"):
    assert abs(s[k] - f[k]) < 1e-9, (k, s[k], f[k])
# An open drive learns the scale: most of its information from the fixes, and the estimate
# within 4 sigma of the truth.
assert f["scale_learnt"] > 0.9, f
for k, i in (("c_l", 0), ("c_r", 1), ("wheelbase", 2)):
    assert abs(f[k] - s["truth_" + k]) < 4 * s["sigma"][i], (k, f[k], s["truth_" + k], s["sigma"][i])
PY
check "fit-fixes equals the simulation's fit and learns the scale" $?
args=(--wheel-diameter 0.15 --counts-per-rev 2048 --gear-ratio 16 --wheelbase 0.34)

# Headings in degrees: refused, naming the file, the line and theta.
python3 - "$F" "$tmp/deg.csv" <<'PY'
import sys
rows = open(sys.argv[1]).read().splitlines()
f = rows[3].split(","); f[3] = "90"; rows[3] = ",".join(f)
open(sys.argv[2], "w").write("\n".join(rows) + "\n")
PY
run "$ODOMCTL" calib fit-fixes --ticks "$T" --fixes "$tmp/deg.csv" "${args[@]}" >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "fixes in degrees exit 2 (got $rc)" $?
grep -q "deg.csv:4: field .theta. = 90 is outside.*looks like degrees" "$tmp/err"; rc_=$?; check "degrees named: $(cat "$tmp/err")" $rc_
[ ! -s "$tmp/out" ]; check "degrees: nothing on stdout" $?

# A fix after the log's end: refused, naming the fix and the span.
python3 - "$F" "$tmp/late.csv" <<'PY'
import sys
rows = open(sys.argv[1]).read().splitlines()
f = rows[-1].split(","); f[0] = str(float(f[0]) + 100.0); rows[-1] = ",".join(f)
open(sys.argv[2], "w").write("\n".join(rows) + "\n")
PY
run "$ODOMCTL" calib fit-fixes --ticks "$T" --fixes "$tmp/late.csv" "${args[@]}" >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "fix outside the log exit 2 (got $rc)" $?
grep -q "late.csv: fix 9 at t = .* is outside the time span of" "$tmp/err"
rc_=$?
check "fix outside the log named: $(cat "$tmp/err")" $rc_

# Too uncertain: the verdict says which bound failed.
run "$ODOMCTL" calib fit-fixes --ticks "$T" --fixes "$F" "${args[@]}" --max-sigma-wheelbase 1e-6 \
  --json >"$tmp/out" 2>"$tmp/err"
check "too-uncertain exit 0" $?
[ "$(jget "$tmp/out" verdict)" = too-uncertain ] &&
  jget "$tmp/out" failed_bound | grep -q "^sigma(b | scale) = .* m > max_sigma_wheelbase = 1e-06 m$"
rc_=$?
check "too-uncertain names the bound: $(cat "$tmp/out")" $rc_
run "$ODOMCTL" calib fit-fixes --ticks "$T" --fixes "$F" "${args[@]}" --max-sigma-wheelbase 1e-6 \
  >"$tmp/out" 2>"$tmp/err"
grep -q "^verdict     too-uncertain: sigma(b | scale) = " "$tmp/out"
rc_=$?
check "too-uncertain text names the bound: $(grep verdict "$tmp/out")" $rc_

# The dock scenario writes no files; an unknown scenario is named.
run "$ODOMCTL" selfcal simulate --ticks-out "$tmp/x.csv" >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q "need --scenario open" "$tmp/err"
rc_=$?
check "dock with --ticks-out exit 2 (got $rc): $(cat "$tmp/err")" $rc_
run "$ODOMCTL" selfcal simulate --scenario park >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q "\-\-scenario = 'park' must be dock or open" "$tmp/err"
rc_=$?
check "unknown scenario exit 2 (got $rc): $(cat "$tmp/err")" $rc_

echo "selfcal cli: $pass passed, $fail failed"
[ "$fail" = 0 ]
