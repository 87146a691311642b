#!/usr/bin/env bash
# Command-line behaviour of odometryd and odomctl: exit codes, stdout/stderr separation, JSON.
set -u
dir=$1
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget

# odomctl replay --json: exactly one JSON object on stdout.
run "$ODOMCTL" replay --ticks "$dir/straight.csv" --wheel-diameter 0.1 --counts-per-rev 1000 \
  --wheelbase 0.3 --json >"$tmp/out" 2>"$tmp/err"
check "replay exit 0" $?
python3 - "$tmp/out" <<'PY'
import json, math, sys
text = open(sys.argv[1]).read()
j = json.loads(text)
assert set(j) == {"x", "y", "theta", "distance", "samples"}, j
assert abs(j["x"] - math.pi * 0.1) < 1e-12 and j["samples"] == 3, j
assert text.count("\n") == 1
PY
check "replay json content" $?

# A malformed row: exit 2, the line named on stderr, nothing on stdout.
printf 't,left,right\n0,0,0\n1,abc,0\n' >"$tmp/bad.csv"
run "$ODOMCTL" replay --ticks "$tmp/bad.csv" --wheel-diameter 0.1 --counts-per-rev 1000 \
  --wheelbase 0.3 --json >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "replay bad row exit 2 (got $rc)" $?
[ ! -s "$tmp/out" ]; check "replay bad row: empty stdout" $?
grep -q "bad.csv:3: field 'left'" "$tmp/err"; check "replay bad row: line named" $?

# A bad option value: exit 2.
run "$ODOMCTL" replay --ticks "$dir/straight.csv" --wheel-diameter -1 --counts-per-rev 1000 \
  --wheelbase 0.3 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "replay bad diameter exit 2 (got $rc)" $?
grep -q "wheel_diameter" "$tmp/err"; check "replay bad diameter named" $?
run "$ODOMCTL" replay --bogus >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "odomctl unknown option exit 2 (got $rc)" $?

# odometryd in virtual time on the simulated robot: a JSON summary, stops by itself.
run "$ODOMETRYD" --virtual-time --json >"$tmp/out" 2>"$tmp/err"
check "odometryd virtual time exit 0" $?
python3 - "$tmp/out" <<'PY'
import json, math, sys
j = json.loads(open(sys.argv[1]).read())
assert -math.pi < j["theta"] <= math.pi, j
assert j["ticks"] > 9000 and j["missed_deadlines"] == 0, j
# The simulated LabMate is uncalibrated: it believes it closed the square, the truth is off.
assert math.hypot(j["x"], j["y"]) < 0.01, j
assert j["position_error"] > 0.02, j
PY
check "odometryd json content" $?

# A config error: exit 2 with file, line and field.
printf '[loop]\nrate_hz = 10\n' >"$tmp/bad.toml"
run "$ODOMETRYD" --config "$tmp/bad.toml" --virtual-time >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "odometryd bad config exit 2 (got $rc)" $?
grep -q "bad.toml:2: loop.rate_hz = 10 is outside the allowed range" "$tmp/err"
check "odometryd bad config message" $?

echo "cli: $pass passed, $fail failed"
[ $fail = 0 ]
