#!/usr/bin/env bash
# odomctl umbmark record (issue 20): a scripted session against odometryd on the simulated robot
# gives the CSV and the calibration of `umbmark simulate`; an interrupted session resumes; bad
# output paths are reported before any work; no per-square lines off a terminal.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget

# --- errors before work: one line, the path once, a newline at the end, nothing written ---
for opt in --store --plot --csv; do
  run "$ODOMCTL" umbmark simulate --passes 2 $opt "$tmp/no/such/dir/out" >"$tmp/out" 2>"$tmp/err"
  rc=$?
  [ $rc = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && [ "$(tail -c 1 "$tmp/err" | od -An -c | tr -d ' ')" = '\n' ] &&
    [ "$(grep -o "no/such/dir/out" "$tmp/err" | wc -l)" = 1 ] && ! grep -q squares "$tmp/err" &&
    [ ! -s "$tmp/out" ] && [ ! -e "$tmp/no" ]
  check "simulate $opt unwritable: exit 2, one line before any square: rc $rc $(cat "$tmp/err")" $?
done
mkdir "$tmp/ro" && chmod 555 "$tmp/ro"
# Root may write into a mode-555 directory (CI runs as root) because of CAP_DAC_OVERRIDE: there
# odomctl runs with that capability (and CAP_DAC_READ_SEARCH) dropped from its bounding set, so
# the directory's mode binds it as it binds anyone (works in chroots and containers too).
skipped=""
ro_run() {
  if [ ! -w "$tmp/ro" ]; then
    run "$@"
  else
    setpriv --bounding-set -dac_override,-dac_read_search ${CROSS_EMULATOR:-} "$@"
  fi
}
if [ -w "$tmp/ro" ] && ! setpriv --bounding-set -dac_override,-dac_read_search true 2>"$tmp/err"; then
  skipped="read-only directory case: root, and setpriv cannot drop CAP_DAC_OVERRIDE ($(cat "$tmp/err"))"
else
  ro_run "$ODOMCTL" errormodel validate --runs 10 --plot "$tmp/ro/p.svg" >/dev/null 2>"$tmp/err"
  rc=$?
  [ $rc = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "ro/p.svg: cannot create" "$tmp/err" &&
    [ ! -e "$tmp/ro/p.svg" ]
  check "errormodel validate --plot in a read-only directory: exit 2, $(cat "$tmp/err")" $?
fi

# --- off a terminal: no progress line per square, one summary ---
run "$ODOMCTL" umbmark simulate --runs 2 --json >/dev/null 2>"$tmp/err"
[ "$(grep -c squares "$tmp/err")" = 2 ] && grep -q "^umbmark simulate: 12 squares driven$" "$tmp/err"
check "simulate off a terminal: header and summary only: $(tr '\n' '|' <"$tmp/err")" $?

# --- the simulated reference: CSV of the first pass and its factors (no noise: the daemon's
# simulated robot has no floor roughness model) ---
run "$ODOMCTL" umbmark simulate --runs 5 --seed 3 --csv "$tmp/sim.csv" --store "$tmp/sim.bin" \
  --json >"$tmp/sim.json" 2>/dev/null
check "simulate --csv --store exit 0" $?

# --- the scripted session: odometryd drives each square in virtual time and broadcasts its
# pose (CAN log); the answers come through a FIFO, written as the session asks for them; the
# "tape" is the simulator's truth: the reference point starts 500 mm from the back wall and 300
# mm from the left wall ---
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = ""\n[sim]\nscenario = "idle"\n' >"$tmp/idle.toml"
for d in cw ccw; do
  printf '[loop]\nstatus_period = 0\n[calibration]\nstore = ""\n[sim]\nscenario = "square-%s"\n' \
    "$d" >"$tmp/$d.toml"
done
mkfifo "$tmp/answers"
run "$ODOMCTL" umbmark record --csv "$tmp/rec.csv" --can-log "$tmp/pose.log" --wheelbase 0.34 \
  --answers "$tmp/answers" --out "$tmp/rec.json" --store "$tmp/rec.bin" >"$tmp/session" 2>&1 &
rec_pid=$!
exec 3>"$tmp/answers"
# wait_for N TEXT: until the session's transcript holds TEXT N times (the session has read
# the pose before the log is replaced by the next daemon run).
seen() { [ "$(grep -c -- "$2" "$tmp/session")" -ge "$1" ]; }
wait_for() {
  poll 60 seen "$1" "$2" && return 0
  echo "timeout waiting for '$2' x$1"; return 1
}
n=0
for d in cw cw cw cw cw ccw ccw ccw ccw ccw; do
  n=$((n + 1))
  run "$ODOMETRYD" --config "$tmp/idle.toml" --virtual-time --duration 0.2 --can-log "$tmp/pose.log" >/dev/null 2>&1
  printf '500\n300\n\n' >&3
  wait_for $n "odometry at start" || break
  run "$ODOMETRYD" --config "$tmp/$d.toml" --virtual-time --json --can-log "$tmp/pose.log" \
    >"$tmp/d.json" 2>/dev/null
  # Tape at the end from the truth [mm]: back 500 + x, left 300 - y; heading [deg] wrapped.
  python3 - "$tmp/d.json" >&3 <<'PY'
import json, math, sys
t = json.load(open(sys.argv[1]))["truth"]
th = math.atan2(math.sin(t["theta"]), math.cos(t["theta"]))
print("")  # Enter: the robot has stopped
print("%.4f\n%.4f\n%.6f" % (500 + 1e3 * t["x"], 300 - 1e3 * t["y"], math.degrees(th)))
PY
  wait_for $n "saved in" || break
done
echo y >&3
exec 3>&-
wait $rec_pid
check "record session exit 0: $(tail -3 "$tmp/session" | tr '\n' '|')" $?
grep -q "odometry at end" "$tmp/session" && grep -q "return error (absolute - odometry)" "$tmp/session" &&
  grep -q "centre of gravity" "$tmp/session" && grep -q "spread sigma" "$tmp/session" &&
  grep -q "back wall" "$tmp/session"
check "record transcript: poses, return error, running c.g. and spread, diagram" $?

# The same CSV: every value within the CAN pose resolution (x, y 0.1 mm, theta 1e-4 rad: the
# daemon's pose is rounded to it on the bus) plus the CSV's own rounding (0.05 mm, 0.5e-5 rad).
python3 - "$tmp/sim.csv" "$tmp/rec.csv" <<'PY'
import sys
a = open(sys.argv[1]).read().splitlines()
b = open(sys.argv[2]).read().splitlines()
assert a[0] == b[0] and len(a) == len(b) == 11, (a, b)
for la, lb in zip(a[1:], b[1:]):
    fa, fb = la.split(","), lb.split(",")
    assert fa[0] == fb[0] and fa[4] == fb[4], (la, lb)
    assert abs(float(fa[1]) - float(fb[1])) <= 1.5e-4 and abs(float(fa[2]) - float(fb[2])) <= 1.5e-4, (la, lb)
    assert abs(float(fa[3]) - float(fb[3])) <= 1.6e-4, (la, lb)
PY
check "record CSV = simulate --csv (same seed) within the CAN resolution" $?
# The same calibration: a 0.15 mm change of a c.g. over 4 L = 16 m moves alpha, beta by
# < 1e-5 rad; b_new by 0.34 * 1e-5 / (pi/2) = 2.2e-6 m, c_l, c_r by b/(2L) * 1e-5 = 4.3e-7.
python3 - "$tmp/sim.json" "$tmp/rec.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["passes"][0]
r = json.load(open(sys.argv[2]))
assert abs(s["b"] - r["b_new"]) < 3e-6, (s, r)
assert abs(s["c_l"] - r["c_l"]) < 1e-6 and abs(s["c_r"] - r["c_r"]) < 1e-6, (s, r)
PY
check "record calibration = simulate's pass 1" $?
run "$ODOMCTL" calib show --store "$tmp/rec.bin" --json >"$tmp/rs.json" 2>/dev/null
run "$ODOMCTL" calib show --store "$tmp/sim.bin" --json >"$tmp/ss.json" 2>/dev/null
python3 - "$tmp/ss.json" "$tmp/rs.json" <<'PY'
import json, sys
s, r = (json.load(open(p)) for p in sys.argv[1:3])
assert s["status"] == r["status"] == "ok", (s, r)
for k in ("c_l", "c_r", "wheelbase"):
    assert abs(s[k] - r[k]) < 3e-6, (k, s, r)
PY
check "record's import into the store = simulate --store" $?

# --- interrupted and resumed: the answers end after two runs; the rerun asks for run 3 ---
run "$ODOMETRYD" --config "$tmp/idle.toml" --virtual-time --duration 0.2 --can-log "$tmp/still.log" >/dev/null 2>&1
printf '500\n300\n\n\n501\n299\n\n500\n300\n\n\n499.5\n300\n\n' >"$tmp/two.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/r2.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/two.txt" >"$tmp/s2" 2>"$tmp/e2"
rc=$?
[ $rc = 1 ] && [ "$(wc -l <"$tmp/r2.csv")" = 3 ] && grep -q "2 runs saved in .*r2.csv: the same command resumes" "$tmp/e2" &&
  grep -q "^cw,0.0010,0.0010,,0$" "$tmp/r2.csv" && grep -q "^cw,-0.0005,0.0000,,0$" "$tmp/r2.csv"
check "record interrupted: exit 1, 2 runs kept: $(tr '\n' '|' <"$tmp/e2")" $?
printf '500\n300\n\n\n500\n300\n\n' >"$tmp/one.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/r2.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/one.txt" >"$tmp/s3" 2>/dev/null
grep -q "2 already in" "$tmp/s3" && grep -q "^Run 3 of 10" "$tmp/s3" && ! grep -q "^Run 1 of" "$tmp/s3" &&
  [ "$(wc -l <"$tmp/r2.csv")" = 4 ]
check "record resumes at run 3" $?
# A bad scripted answer names the file and line; the CSV keeps what it had.
printf '500\nabc\n' >"$tmp/bad.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/r2.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/bad.txt" >/dev/null 2>"$tmp/e4"
grep -q "bad.txt:2: 'abc' is not a number in \[0, 100000\]" "$tmp/e4" && [ "$(wc -l <"$tmp/r2.csv")" = 4 ]
check "record: bad answer names file:line: $(head -1 "$tmp/e4")" $?
run "$ODOMCTL" umbmark record --csv "$tmp/no/dir/r.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/one.txt" >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && [ ! -s "$tmp/out" ]
check "record --csv unwritable: exit 2 before the first question: $(cat "$tmp/err")" $?
# --bumps: the extended-UMBmark runs follow the plain ones and need the heading. With the robot
# standing still, etheta is the typed heading: plain cw 1.0, ccw -0.5 deg; bumps cw 3.0, ccw -2.0
# deg, so eps_theta,nonsys = |3.0 - 1.0| + |-2.0 - (-0.5)| = 3.5 deg = 0.0610865 rad.
printf '500\n300\n\n\n500\n300\n%s\n' 1.0 -0.5 3.0 -2.0 >"$tmp/bumps.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/rb.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --runs 1 --bumps --answers "$tmp/bumps.txt" --out "$tmp/rb.json" >"$tmp/sb" 2>"$tmp/eb"
rc=$?
[ $rc = 0 ] && grep -q "^Run 3 of 4: cw (clockwise, turning right), with bumps" "$tmp/sb" &&
  [ "$(cut -d, -f5 "$tmp/rb.csv" | tr '\n' ' ')" = "bumps 0 0 1 1 " ] &&
  python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['eps_theta_nonsys']; sys.exit(abs(e-0.0610865)>1e-6)" "$tmp/rb.json"
check "record --bumps: 2 + 2 runs, eps_theta,nonsys 3.5 deg: rc $rc $(grep eps_theta "$tmp/sb")" $?
# A bump run without the heading: the scripted answer is refused with file:line, the plain runs
# stay saved.
printf '500\n300\n\n\n500\n300\n%s\n' 1.0 -0.5 >"$tmp/nohead.txt"
printf '500\n300\n\n\n500\n300\n\n' >>"$tmp/nohead.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/rn.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --runs 1 --bumps --answers "$tmp/nohead.txt" >/dev/null 2>"$tmp/en"
rc=$?
[ $rc = 1 ] && grep -q "nohead.txt:21: '' is not a number in \[-180, 180\]" "$tmp/en" &&
  [ "$(wc -l <"$tmp/rn.csv")" = 3 ]
check "record --bumps: a bump run needs the heading (file:line): $(head -1 "$tmp/en")" $?

# Where the poses come from: one source is needed; --config takes the daemon's [can] interface,
# and a daemon config that broadcasts on no interface is said before the first question.
run "$ODOMCTL" umbmark record --csv "$tmp/r3.csv" --wheelbase 0.34 --answers "$tmp/one.txt" \
  >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "one of --can IFACE" "$tmp/err" && [ ! -s "$tmp/out" ]
check "record without a pose source: exit 2, one line: $(cat "$tmp/err")" $?
run "$ODOMCTL" umbmark record --csv "$tmp/r3.csv" --config "$tmp/idle.toml" --wheelbase 0.34 \
  --answers "$tmp/one.txt" >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q 'idle.toml: \[can\] bus is not "socketcan"' "$tmp/err" &&
  [ ! -e "$tmp/r3.csv" ]
check "record --config of a daemon on the simulated bus: exit 2: $(cat "$tmp/err")" $?

echo "cli_umbmark_record: $pass passed, $fail failed"
[ $fail = 0 ] || exit 1
if [ -n "$skipped" ]; then
  echo "SKIP: $skipped"
  exit 77
fi
