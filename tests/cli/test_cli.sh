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

# replay --config (issue 33): the log is replayed with odometryd's own config, read through the
# daemon's reader and tables. A gyro without delay on turns that start and stop: the fusion's
# default delay (2 ms) sees each start and stop as a disagreement (16 on this log), the config's
# `[gyro] delay = 0` none, and the pose is odometry's own.
python3 "$dir/spin_gyro_log.py" "$tmp/spin.csv"
geometry=(--wheel-diameter 0.15 --counts-per-rev 2048 --gear-ratio 16 --wheelbase 0.34)
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" "${geometry[@]}" --json >"$tmp/def.json" 2>"$tmp/err"
check "replay spin log, default fusion: exit 0" $?
printf '[calibration]\nstore = ""\n[gyro]\ndelay = 0\n' >"$tmp/g0.toml"
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" --config "$tmp/g0.toml" --json >"$tmp/cfg.json" 2>"$tmp/err"
check "replay spin log, --config: exit 0" $?
[ "$(jget "$tmp/def.json" gyro.disagreements)" -gt 0 ] && [ "$(jget "$tmp/cfg.json" gyro.disagreements)" = 0 ]
rc_=$?
check "replay --config takes [gyro] delay: $(jget "$tmp/def.json" gyro.disagreements) events with the default, $(jget "$tmp/cfg.json" gyro.disagreements) with the config" $rc_
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" "${geometry[@]}" --no-gyro --json >"$tmp/odo.json" 2>/dev/null
[ "$(jget "$tmp/cfg.json" theta)" = "$(jget "$tmp/odo.json" theta)" ]
check "replay --config, nothing flagged: the heading is odometry's" $?
printf '[gyro]\nwindow = 0.015\n' >"$tmp/gbad.toml"
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" --config "$tmp/gbad.toml" >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q "gbad.toml:2: gyro.window = 0.015 is outside the allowed range \[0.02, 10\] s" "$tmp/err"
rc_=$?
check "replay --config: a bad key is the daemon's message with its line (got $rc: $(cat "$tmp/err"))" $rc_
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" --config "$tmp/g0.toml" --wheelbase 0.3 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q -- "--config excludes --wheelbase" "$tmp/err"
check "replay --config with a geometry option: exit 2 (got $rc)" $?
run "$ODOMCTL" replay --ticks "$tmp/spin.csv" --counts-per-rev 2048 --wheelbase 0.34 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ] && grep -q -- "--wheel-diameter is required (or --config FILE" "$tmp/err"
check "replay without geometry or --config: exit 2 naming the option (got $rc)" $?

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
