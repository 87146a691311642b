# lib.sh - what every CLI test script shares; sourced, not run:  . "$(dirname "$0")/lib.sh"
# run CMD...      runs a target binary (under the cross build's emulator when CROSS_EMULATOR is set)
# check NAME RC   counts a check as passed when RC is 0, else prints "FAIL: NAME". A NAME with a
#                 command substitution sets $? before RC is expanded: take the status first
#                 (`rc_=$?` on the line before); `check "... $(cat err)" $?` always passed (39
#                 checks until stop 40)
# $tmp            a scratch directory removed at exit
# jget FILE KEY   prints the value at the dotted KEY of the JSON object in FILE
# poll SECONDS CMD...  runs CMD every 0.1 s until it succeeds (at most SECONDS); non-zero on timeout
# wait_text FILE TEXT  waits until FILE holds TEXT (at most 30 s); non-zero on timeout
# start_live_log LOG DRIVE  a daemon's log being written at LOG (live_log.py), $relay its pid
# serial_config PROTOCOL DEVICE [BAUD [SECTIONS]]  writes $tmp/serial.toml: [encoder] serial on
#                 DEVICE, store and state in $tmp; SECTIONS (TOML text) goes first
# own_mount_ns    sets ns to unshare's options for a mount namespace of this user's own
#                 (--map-root-user unless root); non-zero when none can be made here
set -u
run() { ${CROSS_EMULATOR:-} "$@"; }
fail=0; pass=0
check() {  # check NAME CONDITION-RESULT
  if [ "$2" = 0 ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $1"; fi
}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
jget() { python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); v=j
for k in sys.argv[2].split("."): v=v[k]
print(v)' "$1" "$2"; }
poll() {
  local i n=$(($1 * 10))
  shift
  for i in $(seq "$n"); do
    "$@" && return 0
    sleep 0.1
  done
  return 1
}
wait_text() { poll 30 grep -qs -- "$2" "$1"; }
# start_live_log LOG DRIVE: a candump log being written at LOG by tests/cli/live_log.py from the
# frames of a virtual-time cw square (ODOMETRYD); a line appended to DRIVE drives the square.
# Sets relay (its pid: the caller kills it); returns once LOG holds a pose.
start_live_log() {
  printf '[loop]\nstatus_period = 0\n[calibration]\nstore = ""\n[sim]\nscenario = "square-cw"\n' \
    >"$tmp/live_sq.toml"
  run "$ODOMETRYD" --config "$tmp/live_sq.toml" --virtual-time --can-log "$tmp/live_sq.log" \
    >/dev/null 2>&1
  : >"$2"
  python3 "$(dirname "${BASH_SOURCE[0]}")/live_log.py" "$tmp/live_sq.log" "$1" "$2" &
  relay=$!
  poll 5 grep -qs " 411#" "$1"
}
# serial_config PROTOCOL DEVICE [BAUD [SECTIONS]]: odometryd's config for the serial counts
# backend (issue 37) as the serial tests run it: reopen after 0.1 s, 3 s for the first record,
# the calibration store and the state record in $tmp; SECTIONS (e.g. "[loop]\nrate_hz = 500")
# first.
serial_config() {
  : >"$tmp/serial.toml"
  if [ -n "${4:-}" ]; then printf '%b\n' "$4" >"$tmp/serial.toml"; fi  # no blank line: the
  # bad-config checks name the line of a key
  cat >>"$tmp/serial.toml" <<TOML
[encoder]
backend = "serial"
[serial]
device = "$2"
protocol = "$1"
baud = ${3:-115200}
reopen_period = 0.1
start_wait = 3.0
[calibration]
store = "$tmp/cal.bin"
backend = "file"
[resume]
path = "$tmp/state.bin"
TOML
}
own_mount_ns() {
  ns=(--mount)
  [[ $(id -u) == 0 ]] || ns+=(--map-root-user)
  unshare "${ns[@]}" true 2>/dev/null
}
