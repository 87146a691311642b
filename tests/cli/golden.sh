#!/usr/bin/env bash
# Golden CLI outputs: a fixed set of deterministic odometryd / odomctl commands whose exit code,
# stdout, stderr and output files must stay byte-identical (issue 15: a reshape changes no
# behaviour). The binaries are called through links named odometryd / odomctl from a scratch
# directory with relative paths, so no build path or temporary name enters the outputs.
# usage: golden.sh check|record GOLDEN_DIR CLI_DIR   (env ODOMETRYD, ODOMCTL, CROSS_EMULATOR)
#   check:  runs the set and compares with GOLDEN_DIR, one FAIL line per differing file
#   record: writes the outputs into GOLDEN_DIR (only when behaviour is meant to change)
set -u
mode=$1
. "$(dirname "$0")/lib.sh"  # run, check, $tmp
# The goldens are the outputs of a machine without the package: odometryd's default store
# /var/lib/odometryd/calibration.bin is reported as "neither ... nor its directory exists yet".
# Where that directory exists (the package installed, a store made by hand), the set runs in a
# mount namespace of its own with an empty /var/lib over the real one: the machine's files are
# neither read nor touched, and the outputs are those of the goldens' machine.
if [[ -e /var/lib/odometryd && -z ${ODO_GOLDEN_OWN_VAR_LIB:-} ]]; then
  if ! own_mount_ns; then
    echo "golden: SKIPPED: /var/lib/odometryd exists and this user cannot make a mount namespace" \
      "to run without it (unshare ${ns[*]})"
    exit 77
  fi
  echo "golden: /var/lib/odometryd exists: the set runs with an empty /var/lib of its own"
  rm -rf "$tmp"  # exec skips lib.sh's exit trap; the run below makes its own
  exec unshare "${ns[@]}" env ODO_GOLDEN_OWN_VAR_LIB=1 bash -c \
    'mount -t tmpfs golden-var-lib /var/lib && exec bash "$0" "$@"' "$0" "$@"
fi
mkdir -p "$2"
golden=$(cd "$2" && pwd)
clidir=$(cd "$3" && pwd)
got="$tmp/got"
mkdir -p "$got" "$tmp/w/bin"
ln -s "$ODOMETRYD" "$tmp/w/bin/odometryd"
ln -s "$ODOMCTL" "$tmp/w/bin/odomctl"
cd "$tmp/w" || exit 1
cp "$clidir/straight.csv" straight.csv

# case NAME CMD...: runs CMD, keeps "exit N", stdout and stderr in $got/NAME.txt (the time a
# calibration record was made, read from the system clock, replaced by a placeholder).
case_() {
  local name=$1
  shift
  run "$@" >stdout 2>stderr
  local rc=$?
  { echo "exit $rc"; echo "--- stdout"; cat stdout; echo "--- stderr"; cat stderr; } |
    sed -E 's/[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9]{2}:[0-9]{2}:[0-9]{2}Z/<utc>/g; s/"time": ?[0-9]{9,}/"time":<now>/g' \
      >"$got/$name.txt"
}
# keep FILE NAME: an output file of a command, compared too.
keep() { cp "$1" "$got/$2"; }
# rebase_candump IN OUT: candump -L log with its wall-clock stamps moved so that the first frame
# is at 1700000000.000000 (odometryd stamps frames with CLOCK_REALTIME at loop time zero).
rebase_candump() {
  python3 - "$1" "$2" <<'PY'
import re, sys
lines = open(sys.argv[1]).read().splitlines()
t0 = None
with open(sys.argv[2], "w") as out:
    for ln in lines:
        m = re.match(r"\((\d+)\.(\d{6})\) (.*)$", ln)
        us = int(m.group(1)) * 1000000 + int(m.group(2))
        t0 = us if t0 is None else t0
        us = us - t0 + 1700000000 * 1000000
        out.write("(%d.%06d) %s\n" % (us // 1000000, us % 1000000, m.group(3)))
PY
}

D=bin/odometryd
C=bin/odomctl

# --- odometryd: help, version, virtual-time runs ---
case_ d_help $D --help
case_ d_version $D --version
case_ d_square_json $D --virtual-time --json
case_ d_square_stats $D --virtual-time --duration 5 --stats
case_ d_square_log $D --virtual-time --duration 3
printf '[encoder]\nbackend = "hctl1100"\n[hctl1100]\nbus = "sim"\nlatch = "lsb"\nbus_cycle = 2e-6\n' >h.toml
case_ d_hctl_json $D --config h.toml --virtual-time --duration 10 --json
printf '[encoder]\nbackend = "can"\n[can_encoder]\nbus = "sim"\nnode_left = 3\nnode_right = 7\n' >c.toml
case_ d_canenc_json $D --config c.toml --virtual-time --duration 10 --json
printf '[encoder]\nbackend = "can"\n[can_encoder]\nbus = "sim"\nsim_stop_left_after = 1.0\n' >cs.toml
case_ d_canenc_stale $D --config cs.toml --virtual-time --duration 3 --json
printf '[loop]\nrate_hz = 10\n' >bad.toml
case_ d_bad_rate $D --config bad.toml --virtual-time
printf '[encoder]\nbackend = "gpio"\n[gpio]\nchip = "/dev/gpiochip-none"\n' >g.toml
case_ d_gpio_missing $D --config g.toml --duration 1
printf '[encoder]\nbackend = "spinning"\n' >bc.toml
case_ d_bad_choice $D --config bc.toml --virtual-time
printf '[can]\nbus = "none"\n' >none.toml
case_ d_can_none $D --config none.toml --virtual-time --duration 1 --json
case_ d_bad_option $D --bogus
for f in "$clidir"/../fuzz/corpus/config/*.toml; do
  b=$(basename "$f" .toml)
  cp "$f" "cfg_$b.toml"
  case_ "d_cfg_$b" $D --config "cfg_$b.toml" --virtual-time --duration 1 --json
done

# --- CAN: a whole square logged, rebased, decoded ---
case_ d_can_log $D --virtual-time --json --can-log can.log
rebase_candump can.log can0.log
keep can0.log can0.log
case_ c_decode $C decode can0.log
case_ c_decode_csv $C decode --csv can0.log
printf '(1700000000.000001) vcan0 418#3930007BF0FF1027\n(1700000000.000002) vcan0 418#\n' >cmd.log
case_ c_decode_cmd $C decode cmd.log
printf '(1700000000.000001) vcan0 410#0000000000000000\n(17000 vcan0 410#00\n' >badc.log
case_ c_decode_bad $C decode badc.log
case_ c_decode_missing $C decode missing.log

# --- odomctl: help, version, replay ---
case_ c_help $C --help
case_ c_version $C --version
for sub in replay calib errormodel umbmark decode; do case_ "c_help_$sub" $C $sub --help; done
for sub in "calib show" "calib set" "calib import" "calib export" "calib reset" \
  "errormodel validate" "errormodel fit" "umbmark compute" "umbmark scale" "umbmark simulate"; do
  # shellcheck disable=SC2086
  case_ "c_help_${sub// /_}" $C $sub --help
done
case_ c_replay_json $C replay --ticks straight.csv --wheel-diameter 0.1 --counts-per-rev 1000 \
  --wheelbase 0.3 --json
case_ c_replay_text $C replay --ticks straight.csv --wheel-diameter 0.1 --counts-per-rev 1000 \
  --wheelbase 0.3
printf 't,left,right\n0,0,0\n1,abc,0\n' >badr.csv
case_ c_replay_bad $C replay --ticks badr.csv --wheel-diameter 0.1 --counts-per-rev 1000 \
  --wheelbase 0.3 --json
case_ c_replay_baddiam $C replay --ticks straight.csv --wheel-diameter -1 --counts-per-rev 1000 \
  --wheelbase 0.3
case_ c_bogus $C replay --bogus
for f in "$clidir"/../fuzz/corpus/replay/*.csv; do
  b=$(basename "$f" .csv)
  cp "$f" "rp_$b.csv"
  case_ "c_replay_$b" $C replay --ticks "rp_$b.csv" --wheel-diameter 0.1 --counts-per-rev 1000 \
    --wheelbase 0.3 --json
done

# --- odomctl calib on a file store ---
S=(--store cal.bin)
case_ c_calib_show_blank $C calib show "${S[@]}" --json
case_ c_calib_set1 $C calib set "${S[@]}" --cl 0.998 --wheelbase 0.337
case_ c_calib_set2 $C calib set "${S[@]}" --cr 1.002 --wheel-diameter 0.1502
case_ c_calib_show $C calib show "${S[@]}"
case_ c_calib_show_json $C calib show "${S[@]}" --json
case_ c_calib_set_bad $C calib set "${S[@]}" --cl 1.5
case_ c_calib_set_none $C calib set "${S[@]}"
case_ c_calib_export $C calib export "${S[@]}"
printf '{"c_l": 0.5, "c_r": 1.0}\n' >badj.json
case_ c_calib_import_bad $C calib import "${S[@]}" badj.json
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "cal.bin"\n' >d.toml
case_ d_with_store $D --config d.toml --virtual-time --duration 1 --json
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "/dev/mtd99"\n' >dx.toml
case_ d_store_device_missing $D --config dx.toml --virtual-time --duration 1 --json
case_ c_calib_reset $C calib reset "${S[@]}"
case_ c_calib_export_blank $C calib export "${S[@]}"
for f in "$clidir"/../fuzz/corpus/calibjson/*.json; do
  b=$(basename "$f" .json)
  cp "$f" "cj_$b.json"
  case_ "c_calib_import_$b" $C calib import --store "cj_$b.bin" "cj_$b.json"
  case_ "c_calib_show_$b" $C calib show --store "cj_$b.bin" --json
done

# --- odomctl umbmark ---
cp "$clidir/umbmark_runs.csv" runs.csv  # the hand-made set of test_umbmark.sh
case_ c_umb_compute_json $C umbmark compute --runs runs.csv --side 4 --wheelbase 0.34 --json
case_ c_umb_compute_text $C umbmark compute --runs runs.csv --side 4 --wheelbase 0.34
case_ c_umb_compute_missing $C umbmark compute --runs nonexistent.csv --side 4 --wheelbase 0.34
for f in "$clidir"/../fuzz/corpus/umbmark/*.csv; do
  b=$(basename "$f" .csv)
  cp "$f" "um_$b.csv"
  case_ "c_umb_compute_$b" $C umbmark compute --runs "um_$b.csv" --side 4 --wheelbase 0.34 --json
done
case_ c_umb_scale $C umbmark scale --calculated 3.003 --measured 3.0 --diameter 0.15 --json
case_ c_umb_scale_text $C umbmark scale --calculated 3.003 --measured 3.0 --diameter 0.15
case_ c_umb_scale_bad $C umbmark scale --calculated 3.0 --measured 0 --diameter 0.15
case_ c_umb_sim $C umbmark simulate --runs 1 --passes 2 --seed 5 --plot u.svg --store sim.bin --json
keep u.svg umb_sim.svg
case_ c_umb_sim_text $C umbmark simulate --runs 2 --passes 1 --seed 9
case_ c_umb_sim_bad $C umbmark simulate --runs 0
case_ c_umb_sim_noise $C umbmark simulate --noise loud
case_ c_umb_sim_skid4 $C umbmark simulate --robot skid4 --runs 1
case_ c_umb_sim_skid4_json $C umbmark simulate --robot skid4 --runs 1 --json
case_ c_umb_sim_robot_bad $C umbmark simulate --robot foo
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "sim.bin"\n' >d2.toml
case_ d_with_sim_store $D --config d2.toml --virtual-time --duration 1 --json

# --- odomctl errormodel ---
case_ c_em_validate $C errormodel validate --runs 300 --path arc --k-left 0.0004 \
  --k-right 0.00058 --wheelbase 0.34 --seed 3 --plot e.svg --csv runs_em.csv --json
keep e.svg em_validate.svg
keep runs_em.csv em_runs.csv
case_ c_em_validate_outback $C errormodel validate --runs 400 --seed 11 --csv ob.csv --plot ob.svg
keep ob.csv em_ob.csv
keep ob.svg em_ob.svg
case_ c_em_fit_json $C errormodel fit ob.csv --distance 10 --wheelbase 0.34 --json
case_ c_em_fit_text $C errormodel fit ob.csv --distance 10 --wheelbase 0.34
case_ c_em_fit_badwb $C errormodel fit ob.csv --wheelbase 34
for bad in "--runs 1" "--path square" "--k-left -1" "--k-right 0.5" "--wheelbase 0" "--runs x"; do
  # shellcheck disable=SC2086
  case_ "c_em_validate_bad_${bad// /_}" $C errormodel validate $bad --json
done
for f in "$clidir"/../fuzz/corpus/errormodel/*.csv; do
  b=$(basename "$f" .csv)
  cp "$f" "em_$b.csv"
  case_ "c_em_fit_$b" $C errormodel fit "em_$b.csv" --json
done

# Outputs over 64 KiB (the whole square's CAN log and its decodings, the SVGs) are kept as their
# SHA-256 only, so the golden folder stays small; compare a fresh record to see such a diff.
for f in "$got"/*; do
  if [ "$(wc -c <"$f")" -gt 65536 ]; then
    (cd "$got" && sha256sum "$(basename "$f")") >"$f.sha256"
    rm "$f"
  fi
done
if [ "$mode" = record ]; then
  rm -rf "$golden"
  mkdir -p "$golden"
  cp "$got"/* "$golden"/
  echo "golden: recorded $(ls "$golden" | wc -l) files into $golden"
  exit 0
fi
# The status of each comparison is taken before the message is built: a command substitution in
# check's first argument would otherwise set the $? that its second argument reads (every
# comparison then counted as passed, whatever it found: the case until stop 36).
# close_text A B: the same text up to a relative 1e-12 in each number (the text between numbers
# byte-identical). Only for a cross build (under its emulator), whose libm rounds some
# sin/cos/atan2/exp results in the last bit differently from amd64's (armhf: em_ob.csv in the
# 16th digit; aarch64: umbmark's r_cg_ccw, a stale run's position_error); natively every byte
# must be the same.
close_text() {
  python3 - "$1" "$2" <<'PY'
import re, sys
num = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
a, b = (open(p, encoding="utf-8", errors="surrogateescape").read() for p in sys.argv[1:3])
def close(x, y):
    u, v = float(x), float(y)
    return u == v or abs(u - v) <= 1e-12 * max(abs(u), abs(v))
ok = num.split(a) == num.split(b) and len(num.findall(a)) == len(num.findall(b)) and \
    all(close(x, y) for x, y in zip(num.findall(a), num.findall(b)))
sys.exit(0 if ok else 1)
PY
}
for f in "$golden"/*; do
  b=$(basename "$f")
  cmp -s "$f" "$got/$b"
  rc=$?
  if [ $rc != 0 ] && [ -n "${CROSS_EMULATOR:-}" ] && [[ $b != *.sha256 ]] && [ -e "$got/$b" ]; then
    close_text "$f" "$got/$b" && rc=0
  fi
  check "$b identical$( [ -e "$got/$b" ] && diff "$f" "$got/$b" | head -6 | sed 's/^/\n  /' | tr -d '\r')" $rc
done
for f in "$got"/*; do
  b=$(basename "$f")
  [ -e "$golden/$b" ]
  rc=$?
  check "$b has a golden file" $rc
done
echo "golden cli: $pass passed, $fail failed"
[ "$fail" = 0 ]
