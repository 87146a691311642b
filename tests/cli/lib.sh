# lib.sh - what every CLI test script shares; sourced, not run:  . "$(dirname "$0")/lib.sh"
# run CMD...      runs a target binary (under the cross build's emulator when CROSS_EMULATOR is set)
# check NAME RC   counts a check as passed when RC is 0, else prints "FAIL: NAME"
# $tmp            a scratch directory removed at exit
# jget FILE KEY   prints the value at the dotted KEY of the JSON object in FILE
# poll SECONDS CMD...  runs CMD every 0.1 s until it succeeds (at most SECONDS); non-zero on timeout
# wait_text FILE TEXT  waits until FILE holds TEXT (at most 30 s); non-zero on timeout
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
