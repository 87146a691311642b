#!/usr/bin/env bash
# Issue 35 item 6: the messages a person needs where odometryd and odomctl used to be silent or
# blamed the wrong thing: a calibration store that does not exist (yet, or a typo in its
# directory), a missing state file, a loop rate that fits no default [can] rate (blamed on the
# key written, with file:line), an unopenable --can-log (blamed on the option), and `odomctl
# selfcal simulate`, which is not odometryd and stores nothing real (item 8).
. "$(dirname "$0")/lib.sh"  # run, check, $tmp
cd "$tmp" || exit 1

# A store path whose file does not exist yet: uncalibrated as before (exit 0, JSON status kept),
# and a note that the first write creates it; nothing is created.
run "$ODOMCTL" calib show --store new.bin >out 2>err
[ $? = 0 ] && grep -q '^status: uncalibrated' out &&
  grep -qx 'note: new.bin does not exist yet; it is created when a calibration is first stored (odomctl calib set, calib import, umbmark record --store)' out
ok=$?  # before the message: its $(...) would set $?
check "calib show, no file yet: exit 0, note ($(tail -1 out))" $ok
run "$ODOMCTL" calib show --store new.bin --json >out 2>err
[ $? = 0 ] && [ "$(jget out status)" = uncalibrated ] && jget out note | grep -q '^new.bin does not exist yet'
check "calib show --json, no file yet: status uncalibrated, note" $?
[ ! -e new.bin ]
check "calib show creates nothing" $?
# Its directory missing too: most likely a typo; exit 1 with the reason on stderr.
run "$ODOMCTL" calib show --store nodir/cal.bin >out 2>err
[ $? = 1 ] && grep -qx 'odomctl calib show: neither nodir/cal.bin nor its directory nodir exists (a typo in the path?)' err
ok=$?  # before the message: its $(...) would set $?
check "calib show, directory missing: exit 1, typo? ($(cat err))" $ok
run "$ODOMCTL" calib export --store new.bin >out 2>err
[ $? = 1 ] && [ ! -s out ] && grep -q '^odomctl calib export: new.bin does not exist yet.*; nothing to export$' err
check "calib export, no file yet: exit 1, says so" $?
# odometryd says the same at start and runs on nominal values.
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "nodir/cal.bin"\n' >typo.toml
run "$ODOMETRYD" --config typo.toml --virtual-time --duration 1 >err 2>&1  # log on stdout
[ $? = 0 ] && grep -qx 'odometryd: calibration nodir/cal.bin (file): uncalibrated (neither nodir/cal.bin nor its directory nodir exists (a typo in the path?)); running on nominal values' err
ok=$?  # before the message: its $(...) would set $?
check "odometryd, store directory missing: typo? ($(head -1 err))" $ok
printf '[loop]\nstatus_period = 0\n[calibration]\nstore = "later.bin"\n' >later.toml
run "$ODOMETRYD" --config later.toml --virtual-time --duration 1 >err 2>&1  # log on stdout
[ $? = 0 ] && grep -q '^odometryd: calibration later.bin (file): uncalibrated (later.bin does not exist yet; it is created' err
ok=$?  # before the message: its $(...) would set $?
check "odometryd, store file not yet written: says it will be created ($(head -1 err))" $ok

# State file.
run "$ODOMCTL" state show --path none.bin >out 2>err
[ $? = 1 ] && grep -qx 'odomctl state show: no state file yet at none.bin (odometryd writes it while it runs)' err
ok=$?  # before the message: its $(...) would set $?
check "state show, no file: 'no state file yet at PATH' ($(cat err))" $ok

# rate_hz = 100.5: can.pose_hz (default 50) cannot be derived; the key the user wrote is named,
# with its line. A [can] rate the user wrote is still blamed on itself.
printf '# robot\n[loop]\nrate_hz = 100.5\n' >rate.toml
run "$ODOMETRYD" --config rate.toml --virtual-time --duration 1 >out 2>err
[ $? = 2 ] && grep -q '^odometryd: rate.toml:3: loop.rate_hz = 100.5 Hz is not a whole multiple of can.pose_hz = 50 Hz (its default)' err
ok=$?  # before the message: its $(...) would set $?
check "rate_hz = 100.5: blamed on loop.rate_hz at rate.toml:3 ($(cat err))" $ok
printf '[loop]\nrate_hz = 100.5\n[can]\npose_hz = 50\n' >rate2.toml
run "$ODOMETRYD" --config rate2.toml --virtual-time --duration 1 >out 2>err
[ $? = 2 ] && grep -q '^odometryd: rate2.toml:4: can.pose_hz = 50 Hz must be 0 or loop.rate_hz / n' err
check "can.pose_hz written: blamed on it at rate2.toml:4" $?

# --can-log into a missing directory: the option's fault, not the built-in config's.
run "$ODOMETRYD" --virtual-time --duration 1 --can-log nodir/x.log >out 2>err
[ $? = 2 ] && grep -qx 'odometryd: --can-log nodir/x.log: cannot open the CAN log for writing (No such file or directory)' err &&
  ! grep -q 'built-in' err
ok=$?  # before the message: its $(...) would set $?
check "--can-log nodir/x.log: blamed on the option ($(tail -1 err))" $ok

# odomctl selfcal simulate speaks as itself and stores nothing real.
run "$ODOMCTL" selfcal simulate --excursions 3 --score-runs 5 --fit-every 1 --min-fixes 2 >out 2>err
[ $? = 0 ] && grep -q '^odomctl selfcal simulate: ' out && ! grep -q 'odometryd' out &&
  ! grep -q '(stored)' out
check "selfcal simulate: its lines are odomctl's, no '(stored)'" $?

echo "messages: $pass passed, $fail failed"
[ "$fail" = 0 ]
