#!/usr/bin/env bash
# Issue 35 item 8: the README's example status line is what odometryd prints. A real-time run of
# 3.5 s gives status lines at about 1, 2 and 3 s; each line's shape (every number replaced by N,
# runs of spaces by one) must equal the shape of the README's example (the first line starting
# with "t=" in the README), so a renamed, added or dropped field fails here. Also: the p99
# figures are "-" until the first summary (256 ticks) and the README says so; virtual time prints
# no status lines and the README says so.
# usage: test_readme_status.sh README   (env ODOMETRYD, CROSS_EMULATOR)
. "$(dirname "$0")/lib.sh"  # run, check, $tmp
readme=$1

run "$ODOMETRYD" --duration 3.5 >"$tmp/out" 2>&1
check "odometryd --duration 3.5: exit 0" $?
grep '^t=' "$tmp/out" >"$tmp/lines"
[ "$(wc -l <"$tmp/lines")" -ge 3 ]
ok=$?  # before the message: its $(...) would set $?
check "real time: a status line a second ($(wc -l <"$tmp/lines") lines)" $ok

shape() { sed -E 's/[+-]?[0-9]+(\.[0-9]+)?/N/g; s/ +/ /g'; }
example=$(grep -m1 '^t=' "$readme")
[ -n "$example" ]
check "README has an example status line" $?
want=$(echo "$example" | shape)
got=$(tail -1 "$tmp/lines" | shape)
[ "$want" = "$got" ]
check "README's status line has the daemon's format
  README: $want
  daemon: $got" $?
# The first line (before 256 ticks) has no percentiles yet: "-", not a 0 that looks measured.
head -1 "$tmp/lines" | grep -q 'lat p99/max=-/[0-9]* us  cmp p99=- us'
ok=$?  # before the message: its $(...) would set $?
check "first status line: p99 '-' until there are samples ($(head -1 "$tmp/lines" | grep -o 'lat.*us  m'))" $ok
grep -q 'p99 figures read `-`' "$readme"
check "README says the p99 figures read - at first" $?

run "$ODOMETRYD" --virtual-time --duration 3 >"$tmp/vout" 2>&1
[ $? = 0 ] && ! grep -q '^t=' "$tmp/vout"
check "virtual time: no status lines" $?
grep -q 'prints no status lines' "$readme"
check "README says virtual time prints no status lines" $?

echo "readme status: $pass passed, $fail failed"
[ "$fail" = 0 ]
