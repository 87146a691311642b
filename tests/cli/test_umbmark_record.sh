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
  rc_=$?
  check "simulate $opt unwritable: exit 2, one line before any square: rc $rc $(cat "$tmp/err")" $rc_
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
  rc_=$?
  check "errormodel validate --plot in a read-only directory: exit 2, $(cat "$tmp/err")" $rc_
fi

# --- off a terminal: no progress line per square, one summary ---
run "$ODOMCTL" umbmark simulate --runs 2 --json >/dev/null 2>"$tmp/err"
# 8: 2 cw + 2 ccw before the one pass and 4 after it (the check's status was lost until stop 40,
# and its count, 12, from when a first pass always asked for a second: issue 35 item 4).
[ "$(grep -c squares "$tmp/err")" = 2 ] && grep -q "^umbmark simulate: 8 squares driven$" "$tmp/err"
rc_=$?
check "simulate off a terminal: header and summary only: $(tr '\n' '|' <"$tmp/err")" $rc_

# --- the simulated reference: CSV of the first pass and its factors (no noise: the daemon's
# simulated robot has no floor roughness model); 0.5 m squares, as the live daemon drives them ---
run "$ODOMCTL" umbmark simulate --runs 2 --side 0.5 --seed 3 --csv "$tmp/sim.csv" --store "$tmp/sim.bin" \
  --json >"$tmp/sim.json" 2>/dev/null
check "simulate --csv --store exit 0" $?

# --- the live session (issue 35): for each run odometryd starts in REAL time on the simulated
# robot, writing --can-log; the robot stands still for start_delay (the session reads the start
# pose from the growing log), drives a 0.5 m square, and stands still again while the session
# reads the end pose. The answers come through a FIFO, written as the session asks for them; the
# "tape" is the simulator's truth: the reference point starts 500 mm from the back wall and 300
# mm from the left wall ---
for d in cw ccw; do
  printf '[loop]\nstatus_period = 0\n[calibration]\nstore = ""\n[realtime]\npriority = 0\nlock_memory = false\n[sim]\nscenario = "square-%s"\nside = 0.5\nspeed = 1.0\nturn_rate = 5.0\npause = 0.1\nstart_delay = 1.5\n' \
    "$d" >"$tmp/rt_$d.toml"
done
mkfifo "$tmp/answers"
run "$ODOMCTL" umbmark record --csv "$tmp/rec.csv" --can-log "$tmp/pose.log" --wheelbase 0.34 \
  --side 0.5 --runs 2 --answers "$tmp/answers" --out "$tmp/rec.json" --store "$tmp/rec.bin" \
  >"$tmp/session" 2>&1 &
rec_pid=$!
exec 3>"$tmp/answers"
# wait_for N TEXT [FILE]: until the session's transcript holds TEXT N times.
seen() { [ "$(grep -c -- "$2" "${3:-$tmp/session}")" -ge "$1" ]; }
wait_for() {
  poll 60 seen "$@" && return 0
  echo "timeout waiting for '$2' x$1"; return 1
}
has_pose() { grep -qs " 411#" "$tmp/pose.log"; }
n=0
for d in cw cw ccw ccw; do
  n=$((n + 1))
  rm -f "$tmp/pose.log"  # the log of the run before says stopping until the daemon starts anew
  run "$ODOMETRYD" --config "$tmp/rt_$d.toml" --duration 8 --json --can-log "$tmp/pose.log" \
    >"$tmp/d$n.json" 2>"$tmp/d$n.err" &
  dpid=$!
  t0=$(date +%s.%N)
  poll 5 has_pose || echo "no pose in the live log within 5 s"
  printf '500\n300\n\n' >&3
  wait_for $n "odometry at start" || break
  # Enter once the square is driven: start_delay + the scenario, as the daemon says, + 0.3 s.
  wait_text "$tmp/d$n.err" "scenario '" || break
  dur=$(sed -n "s/.*scenario 'square-[a-z]*' (\([0-9.]*\) s).*/\1/p" "$tmp/d$n.err")
  sleep "$(python3 -c "import sys,time; print(max(0.0, float(sys.argv[1]) + float(sys.argv[2]) + 0.3 - time.time()))" "$t0" "$dur")"
  printf '\n' >&3
  wait_for $n "odometry at end" || break
  wait $dpid
  # Tape at the end from the truth [mm]: back 500 + x, left 300 - y; heading [deg] wrapped.
  python3 - "$tmp/d$n.json" >&3 <<'PY'
import json, math, sys
t = json.load(open(sys.argv[1]))["truth"]
th = math.atan2(math.sin(t["theta"]), math.cos(t["theta"]))
print("%.4f\n%.4f\n%.6f" % (500 + 1e3 * t["x"], 300 - 1e3 * t["y"], math.degrees(th)))
PY
  wait_for $n "saved in" || break
done
wait_for 1 "import into" && echo y >&3
exec 3>&-
wait $rec_pid
rc_=$?
check "live record session exit 0: $(tail -3 "$tmp/session" | tr '\n' '|')" $rc_
grep -q "odometry at end" "$tmp/session" && grep -q "return error (absolute - odometry)" "$tmp/session" &&
  grep -q "centre of gravity" "$tmp/session" && grep -q "spread sigma" "$tmp/session" &&
  grep -q "back wall" "$tmp/session"
check "record transcript: poses, return error, running c.g. and spread, diagram" $?
# Every start pose read from the live log is the robot at rest on its mark (the issue's stale
# log gave y -0.3488 m there).
[ "$(grep -c "odometry at start: x 0.0000 m, y 0.0000 m, theta 0.000 deg" "$tmp/session")" = 4 ]
rc_=$?
check "live session: the 4 start poses are the daemon's (0, 0, 0): $(grep "at start" "$tmp/session" | tr '\n' '|')" $rc_
# The CSV rows = the simulator's truth: run i's ex, ey, etheta = truth - odometry at the
# daemon's end (its --json), within the CAN pose resolution (x, y 0.1 mm, theta 1e-4 rad) plus
# the CSV's rounding (0.05 mm, 0.5e-5 rad).
python3 - "$tmp/rec.csv" "$tmp"/d1.json "$tmp"/d2.json "$tmp"/d3.json "$tmp"/d4.json <<'PY'
import json, math, sys
rows = open(sys.argv[1]).read().splitlines()
assert len(rows) == 5, rows
for row, path, d in zip(rows[1:], sys.argv[2:], ["cw", "cw", "ccw", "ccw"]):
    j = json.load(open(path))
    t = j["truth"]
    f = row.split(",")
    w = lambda a: math.atan2(math.sin(a), math.cos(a))
    assert f[0] == d and f[4] == "0", row
    assert abs(float(f[1]) - (t["x"] - j["x"])) <= 1.5e-4, (row, t, j["x"])
    assert abs(float(f[2]) - (t["y"] - j["y"])) <= 1.5e-4, (row, t, j["y"])
    assert abs(float(f[3]) - w(w(t["theta"]) - j["theta"])) <= 1.6e-4, (row, t, j["theta"])
PY
check "live record CSV = the simulator's truth - odometry, run by run" $?
# And the same as `umbmark simulate --csv` of 0.5 m squares (same seed, no noise).
python3 - "$tmp/sim.csv" "$tmp/rec.csv" <<'PY'
import sys
a = open(sys.argv[1]).read().splitlines()
b = open(sys.argv[2]).read().splitlines()
assert a[0] == b[0] and len(a) == len(b) == 5, (a, b)
for la, lb in zip(a[1:], b[1:]):
    fa, fb = la.split(","), lb.split(",")
    assert fa[0] == fb[0] and fa[4] == fb[4], (la, lb)
    assert abs(float(fa[1]) - float(fb[1])) <= 1.5e-4 and abs(float(fa[2]) - float(fb[2])) <= 1.5e-4, (la, lb)
    assert abs(float(fa[3]) - float(fb[3])) <= 1.6e-4, (la, lb)
PY
check "live record CSV = simulate --csv (same seed) within the CAN resolution" $?
# The import shows the factors used during the runs against the new ones with their sigmas (the
# store does not exist yet: nothing else to show), then stores what it showed.
grep -q "the import would store (used during the runs -> new):" "$tmp/session" &&
  grep -q "^  (.*rec.bin does not exist yet; it is created when a calibration is first stored" "$tmp/session" &&
  grep -Eq "^  c_l +1.000000 -> [0-9.]+  \(sigma [0-9.]+\)$" "$tmp/session" &&
  grep -Eq "^  wheelbase +340.0 mm -> [0-9.]+ mm  \(sigma [0-9.]+ mm\)$" "$tmp/session"
rc_=$?
check "record: the import shows old -> new and sigmas: $(grep -A3 "import would" "$tmp/session" | tr '\n' '|')" $rc_
run "$ODOMCTL" calib show --store "$tmp/rec.bin" --json >"$tmp/rs.json" 2>/dev/null
python3 - "$tmp/rs.json" "$tmp/session" "$tmp/rec.json" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
shown = re.search(r"^  c_l +[0-9.]+ -> ([0-9.]+)", open(sys.argv[2]).read(), re.M).group(1)
r = json.load(open(sys.argv[3]))
assert s["status"] == "ok" and abs(s["c_l"] - float(shown)) <= 5e-7, (s, shown)
assert abs(s["c_l"] - r["c_l"]) < 1e-9 and abs(s["wheelbase"] - r["b_new"]) < 1e-9, (s, r)
PY
check "record's import into the store = what it showed and --out" $?

# The same command again: every run is in the CSV, so the session goes straight to the import,
# now over a store that holds the factors just imported. The preview's "old" values are the
# store's (issue 35), and the runs were driven with --current-cl 1 while the store holds others:
# a note says so and how to record again. With the store's values given, no note. Answer N.
printf 'n\n' >"$tmp/no"
resume() {
  run "$ODOMCTL" umbmark record --csv "$tmp/rec.csv" --can-log "$tmp/pose.log" --side 0.5 \
    --runs 2 --answers "$tmp/no" --store "$tmp/rec.bin" "$@" >"$tmp/resume" 2>&1
}
resume --wheelbase 0.34
rc_=$?
check "record resumed with every run saved: exit 0: $(tail -2 "$tmp/resume" | tr '\n' '|')" $rc_
python3 - "$tmp/rs.json" "$tmp/resume" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
t = open(sys.argv[2]).read()
assert re.search(r"^the import would store \(in .*rec\.bin now, sequence %d -> new\):$" % s["sequence"], t, re.M), t
old = float(re.search(r"^  c_l +([0-9.]+) -> ", t, re.M).group(1))
assert abs(old - s["c_l"]) <= 5e-7, (old, s)
b = float(re.search(r"^  wheelbase +([0-9.]+) mm -> ", t, re.M).group(1))
assert abs(b - 1e3 * s["wheelbase"]) <= 0.05, (b, s)
assert "note: the new factors are composed from those the runs were driven with (--current-cl 1.000000" in t, t
assert "not imported." in t, t
PY
check "record resumed: the preview's old values are the store's, with the --current-* note" $?
args=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print("--current-cl %.9f --current-cr %.9f --wheelbase %.9f" % (s["c_l"], s["c_r"], s["wheelbase"]))' "$tmp/rs.json")
# shellcheck disable=SC2086
resume $args
[ $? = 0 ] && grep -q "^the import would store (in .*rec.bin now" "$tmp/resume" && ! grep -q "note:" "$tmp/resume"
check "record resumed with the store's values as --current-*: no note" $?
run "$ODOMCTL" calib show --store "$tmp/rec.bin" --json >"$tmp/rs2.json" 2>/dev/null
cmp -s "$tmp/rs.json" "$tmp/rs2.json"
check "answering N leaves the store as it was" $?

# --- the recorder's logic on a log being written: live_log.py writes the log of a running
# daemon (fresh stamps) from a virtual-time square's frames; each "drive" line in its control
# file drives the square between the two Enters (odometry moves along it, 0 net) ---
start_live_log "$tmp/still.log" "$tmp/drive"
trap 'kill $relay 2>/dev/null; rm -rf "$tmp"' EXIT
# scripted NAME ARGS... RUNS...: `umbmark record ARGS` with its answers through the FIFO
# $tmp/NAME (the error messages name it), transcript $tmp/NAME.out, stderr $tmp/NAME.err; each
# RUN is "BACK0 SIDE0 BACK1 SIDE1 HEADING" [mm, deg; HEADING - is an empty answer], the square
# driven between the Enters. Sets rc to the session's exit code.
scripted() {
  local name=$1 args=() r k=0
  shift
  while [ $# -gt 0 ] && [ "${1%% *}" = "$1" ]; do  # options have no blank, runs do
    args+=("$1"); shift
  done
  rm -f "$tmp/$name"; mkfifo "$tmp/$name"
  run "$ODOMCTL" umbmark record --can-log "$tmp/still.log" --wheelbase 0.34 "${args[@]}" \
    --answers "$tmp/$name" >"$tmp/$name.out" 2>"$tmp/$name.err" &
  local pid=$!
  exec 4>"$tmp/$name"
  for r in "$@"; do
    k=$((k + 1))
    set -- $r
    printf '%s\n%s\n\n' "$1" "$2" >&4
    poll 10 seen $k "odometry at start" "$tmp/$name.out" || break
    echo drive >>"$tmp/drive"
    sleep 0.2
    printf '\n' >&4
    poll 10 seen $k "odometry at end" "$tmp/$name.out" || break
    printf '%s\n%s\n%s\n' "$3" "$4" "$([ "$5" = - ] || echo "$5")" >&4
    poll 10 seen $k "saved in" "$tmp/$name.out" || poll 2 grep -q "stopped;" "$tmp/$name.err" || break
  done
  exec 4>&-
  wait $pid
  rc=$?
}

# --- interrupted and resumed: the answers end after two runs; the rerun asks for run 3 ---
scripted two.txt --csv "$tmp/r2.csv" "500 300 501 299 -" "500 300 499.5 300 -"
[ $rc = 1 ] && [ "$(wc -l <"$tmp/r2.csv")" = 3 ] && grep -q "2 runs saved in .*r2.csv: the same command resumes" "$tmp/two.txt.err" &&
  grep -q "^cw,0.0010,0.0010,,0$" "$tmp/r2.csv" && grep -q "^cw,-0.0005,0.0000,,0$" "$tmp/r2.csv"
rc_=$?
check "record interrupted: exit 1, 2 runs kept: rc $rc $(tr '\n' '|' <"$tmp/two.txt.err")" $rc_
scripted one.txt --csv "$tmp/r2.csv" "500 300 500 300 -"
grep -q "2 already in" "$tmp/one.txt.out" && grep -q "^Run 3 of 10" "$tmp/one.txt.out" && ! grep -q "^Run 1 of" "$tmp/one.txt.out" &&
  [ "$(wc -l <"$tmp/r2.csv")" = 4 ]
check "record resumes at run 3" $?
# A bad scripted answer names the file and line and exits 2 (bad input); the CSV keeps what it had.
printf '500\nabc\n' >"$tmp/bad.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/r2.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/bad.txt" >/dev/null 2>"$tmp/e4"
rc=$?
[ $rc = 2 ] && grep -q "bad.txt:2: 'abc' is not a number in \[0, 100000\]" "$tmp/e4" && [ "$(wc -l <"$tmp/r2.csv")" = 4 ]
rc_=$?
check "record: bad answer names file:line, exit 2: rc $rc $(head -1 "$tmp/e4")" $rc_
# Metres typed where millimetres are asked: refused with the reason (exit 2, file:line).
printf '500\n0.3\n' >"$tmp/metres.txt"
run "$ODOMCTL" umbmark record --csv "$tmp/r2.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/metres.txt" >/dev/null 2>"$tmp/e5"
rc=$?
[ $rc = 2 ] && grep -q "metres.txt:2: 0.3 mm from a wall (under 10 mm): metres typed? type millimetres (0.3 m = 300 mm)" "$tmp/e5" &&
  [ "$(wc -l <"$tmp/r2.csv")" = 4 ]
rc_=$?
check "record: 0.3 where mm are asked is refused: rc $rc $(head -1 "$tmp/e5")" $rc_
run "$ODOMCTL" umbmark record --csv "$tmp/no/dir/r.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/bad.txt" >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && [ ! -s "$tmp/out" ]
rc_=$?
check "record --csv unwritable: exit 2 before the first question: $(cat "$tmp/err")" $rc_
# A return error of 1100 mm on a 4 m square (27.5 % of the side, over 25 %): a mistyped reading,
# refused naming the answer's line (the heading, the last of the end readings: line 7).
scripted far.txt --csv "$tmp/rf.csv" "500 300 1600 300 -"
[ $rc = 2 ] && grep -q "far.txt:7: the return error (ex +1100.0 mm, ey +0.0 mm) is 28 % of the 4 m side (at most 25 % is taken)" "$tmp/far.txt.err" &&
  [ ! -e "$tmp/rf.csv" ]
rc_=$?
check "record: a return error of 28 % of the side is refused: rc $rc $(head -1 "$tmp/far.txt.err")" $rc_
# --bumps: the extended-UMBmark runs follow the plain ones and need the heading. With the
# odometry back where it started, etheta is the typed heading: plain cw 1.0, ccw -0.5 deg; bumps
# cw 3.0, ccw -2.0 deg, so eps_theta,nonsys = |3.0 - 1.0| + |-2.0 - (-0.5)| = 3.5 deg = 0.0610865 rad.
scripted bumps.txt --csv "$tmp/rb.csv" --runs 1 --bumps --out "$tmp/rb.json" \
  "500 300 500 300 1.0" "500 300 500 300 -0.5" "500 300 500 300 3.0" "500 300 500 300 -2.0"
[ $rc = 0 ] && grep -q "^Run 3 of 4: cw (clockwise, turning right), with bumps" "$tmp/bumps.txt.out" &&
  [ "$(cut -d, -f5 "$tmp/rb.csv" | tr '\n' ' ')" = "bumps 0 0 1 1 " ] &&
  python3 -c "import json,sys; e=json.load(open(sys.argv[1]))['eps_theta_nonsys']; sys.exit(abs(e-0.0610865)>1e-6)" "$tmp/rb.json"
rc_=$?
check "record --bumps: 2 + 2 runs, eps_theta,nonsys 3.5 deg: rc $rc $(grep eps_theta "$tmp/bumps.txt.out")" $rc_
# A bump run without the heading: the scripted answer is refused with file:line (exit 2), the
# plain runs stay saved.
scripted nohead.txt --csv "$tmp/rn.csv" --runs 1 --bumps \
  "500 300 500 300 1.0" "500 300 500 300 -0.5" "500 300 500 300 -"
[ $rc = 2 ] && grep -q "nohead.txt:21: '' is not a number in \[-180, 180\]" "$tmp/nohead.txt.err" &&
  [ "$(wc -l <"$tmp/rn.csv")" = 3 ]
rc_=$?
check "record --bumps: a bump run needs the heading (file:line): rc $rc $(head -1 "$tmp/nohead.txt.err")" $rc_

# --- refusals (issue 35): no odometry motion between the two Enters, a stale log, a stopped
# daemon; each says what to do ---
rm -f "$tmp/still2"; mkfifo "$tmp/still2"
run "$ODOMCTL" umbmark record --csv "$tmp/rs.csv" --can-log "$tmp/still.log" --wheelbase 0.34 \
  --answers "$tmp/still2" >"$tmp/still2.out" 2>"$tmp/still2.err" &
pid=$!
exec 4>"$tmp/still2"
printf '500\n300\n\n' >&4
poll 10 seen 1 "odometry at start" "$tmp/still2.out"
printf '\n' >&4  # Enter again without driving
exec 4>&-
wait $pid
rc=$?
[ $rc = 1 ] && grep -q "the odometry moved 0.000 m since the start pose, a square of 4 m is 16 m: drive the square (is --side right?), then press Enter" "$tmp/still2.err" &&
  [ ! -e "$tmp/rs.csv" ]
rc_=$?
check "record: no odometry motion between the Enters is refused: rc $rc $(head -1 "$tmp/still2.err")" $rc_
printf '500\n300\n\n\n500\n300\n\n' >"$tmp/one_still.txt"
# Stale: the relay stops writing (a daemon killed without its last Status frame), 2 s later the
# newest pose is older than 0.5 s.
kill $relay; wait $relay 2>/dev/null
sleep 2
# refused NAME LOG PATTERN: a scripted session on LOG stops at the first pose (exit 1) with
# PATTERN on stderr and writes no CSV.
refused() {
  run "$ODOMCTL" umbmark record --csv "$tmp/rs.csv" --can-log "$2" --wheelbase 0.34 \
    --answers "$tmp/one_still.txt" >/dev/null 2>"$tmp/e_$1"
  rc=$?
  [ $rc = 1 ] && grep -Eq "$3" "$tmp/e_$1" && [ ! -e "$tmp/rs.csv" ]
  rc_=$?
  check "record: $1 is refused: rc $rc $(head -1 "$tmp/e_$1")" $rc_
}
refused "a stale log" "$tmp/still.log" "still.log: the newest pose is [0-9.]+ s old \(at most 0.5 s is taken\), the newest Status frame [0-9.]+ s old: is odometryd running with --can-log .*still.log \(or candump -L writing it\)\? Start it$"
# Stopped: the live session's log ends with the daemon's Status frame that says stopping.
refused "a stopped daemon's log" "$tmp/pose.log" "pose.log: odometryd has stopped \(its last Status frame, [0-9.]+ s old, says stopping\): start it again with --can-log .*pose.log$"

printf '[loop]\nstatus_period = 0\n[calibration]\nstore = ""\n[sim]\nscenario = "idle"\n' >"$tmp/idle.toml"
# Where the poses come from: one source is needed; --config takes the daemon's [can] interface,
# and a daemon config that broadcasts on no interface is said before the first question.
run "$ODOMCTL" umbmark record --csv "$tmp/r3.csv" --wheelbase 0.34 --answers "$tmp/one_still.txt" \
  >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q "one of --can IFACE" "$tmp/err" && [ ! -s "$tmp/out" ]
rc_=$?
check "record without a pose source: exit 2, one line: $(cat "$tmp/err")" $rc_
run "$ODOMCTL" umbmark record --csv "$tmp/r3.csv" --config "$tmp/idle.toml" --wheelbase 0.34 \
  --answers "$tmp/one_still.txt" >"$tmp/out" 2>"$tmp/err"
[ $? = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q 'idle.toml: \[can\] bus is not "socketcan"' "$tmp/err" &&
  [ ! -e "$tmp/r3.csv" ]
rc_=$?
check "record --config of a daemon on the simulated bus: exit 2: $(cat "$tmp/err")" $rc_

echo "cli_umbmark_record: $pass passed, $fail failed"
[ $fail = 0 ] || exit 1
if [ -n "$skipped" ]; then
  echo "SKIP: $skipped"
  exit 77
fi
