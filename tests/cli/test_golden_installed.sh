#!/usr/bin/env bash
# cli_golden_installed: the golden outputs hold on a machine where the package is installed
# (issue 35: two of them read "neither /var/lib/odometryd/calibration.bin nor its directory exists
# yet" and failed where /var/lib/odometryd existed). The directory is made to exist in a mount
# namespace of this test's own (an empty /var/lib over the real one: the machine untouched); in
# it odometryd reports the installed wording, and golden.sh, which then runs its set with an
# empty /var/lib of its own, still matches every golden file.
# usage: test_golden_installed.sh GOLDEN_DIR CLI_DIR   (env ODOMETRYD, ODOMCTL)
. "$(dirname "$0")/lib.sh"
golden=$(cd "$1" && pwd) clidir=$(cd "$2" && pwd) here=$(cd "$(dirname "$0")" && pwd)
if ! own_mount_ns; then
  echo "SKIPPED: this user cannot make a mount namespace (unshare ${ns[*]})"
  exit 77
fi
installed() {  # installed CMD...: CMD with /var/lib/odometryd present, as the package leaves it
  unshare "${ns[@]}" bash -c 'mount -t tmpfs installed /var/lib && mkdir /var/lib/odometryd &&
    exec "$@"' installed "$@"
}
installed "$ODOMETRYD" --virtual-time --duration 0.1 >"$tmp/d.out" 2>&1
grep -q "calibration.bin does not exist yet; it is created" "$tmp/d.out"
check "odometryd in the namespace sees /var/lib/odometryd (the goldens' wording would differ)" $?
installed env ODOMETRYD="$ODOMETRYD" ODOMCTL="$ODOMCTL" \
  bash "$here/golden.sh" check "$golden" "$clidir" >"$tmp/golden.out" 2>&1
rc_=$?
check "golden.sh check passes with /var/lib/odometryd present$(grep -A6 '^FAIL' "$tmp/golden.out" | head -14 | sed 's/^/\n  /')" $rc_
grep -q "^golden: /var/lib/odometryd exists" "$tmp/golden.out"
check "golden.sh said it ran its set with an empty /var/lib of its own" $?
grep -q "golden cli: [1-9][0-9]* passed, 0 failed" "$tmp/golden.out"
check "golden.sh compared files" $?
echo "golden installed: $pass passed, $fail failed"
[ "$fail" = 0 ]
