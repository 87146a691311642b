#!/usr/bin/env bash
# Issue 35 item 7: every --help of odometryd and of each odomctl command and subcommand (found by
# walking the "Subcommands:" lists, so a new command is scanned without editing this file) in the
# project's words: no parser text ("FLOAT:FLOAT in [0 - 1e+09]", "ENUM:value in {...} OR {0,1}",
# "TEXT=default"), a default at most once per option and always as "(default X)", a range at
# most once and always as ", range [lo, hi]", no file named that the repository does not have.
# Also the refusals of the checks behind them (no "Check ... FAILED") and the unknown or missing
# subcommand (item 6).
# usage: test_help_texts.sh SOURCE_DIR   (env ODOMETRYD, ODOMCTL, CROSS_EMULATOR)
. "$(dirname "$0")/lib.sh"  # run, check, $tmp
src=$1

# walk CMD...: "=== CMD" and the help of CMD, then the same for each of its subcommands.
walk() {
  local h s
  h=$(run "$ODOMCTL" "$@" --help)
  printf '=== odomctl %s\n%s\n' "$*" "$h"
  for s in $(echo "$h" | awk '/^Subcommands:/ { f = 1; next } f && NF { print $1 }'); do
    walk "$@" "$s"
  done
}
{
  printf '=== odometryd\n'
  run "$ODOMETRYD" --help
  walk
} >"$tmp/help.txt"
n_help=$(grep -c '^=== ' "$tmp/help.txt")
[ "$n_help" -ge 25 ]
check "help texts found: $n_help (odometryd and every odomctl command)" $?

python3 - "$tmp/help.txt" "$src" "$tmp/entries.txt" >"$tmp/leaks.txt" <<'PY'
import os, re, sys
text, src = open(sys.argv[1]).read(), sys.argv[2]
leaks = []
cmd = "?"
entries = []  # (command, option entry with its continuation lines joined)
for line in text.splitlines():
    if line.startswith("=== "):
        cmd = line[4:]
    elif re.match(r"^  \S", line):
        entries.append([cmd, line.strip()])
    elif re.match(r"^ {20,}\S", line) and entries:
        entries[-1][1] += " " + line.strip()
parser_words = [r"\b[A-Z]+:[A-Z{\[]", r"\bENUM\b", r"value in \{", r"->", r" OR \{", r"FAILED",
                r"^\S+ [A-Z]+=", r"\[[^\]]* - [^\]]*\]", r"\d\.\.\d"]
for c, e in entries:
    for w in parser_words:
        if re.search(w, e):
            leaks.append(f"{c}: parser text /{w}/: {e}")
    d = re.findall(r"default", e, re.I)
    good = re.findall(r"\(default [^()]+\)", e)
    if len(d) > 1 or len(d) != len(good):
        leaks.append(f"{c}: default not once as '(default X)': {e}")
    r = re.findall(r"\[-?[0-9.e+]+, -?[0-9.e+]+\]", e)
    if len(r) > 1 or len(r) != len(re.findall(r", range \[", e)):
        leaks.append(f"{c}: range not once as ', range [lo, hi]': {e}")
for md in set(re.findall(r"\b[A-Z][A-Za-z_]*\.md\b", text)):
    if not os.path.exists(os.path.join(src, md)):
        leaks.append(f"names {md}, which the repository does not have")
open(sys.argv[3], "w").write("".join(f"{c}: {e}\n" for c, e in entries))
print(f"{len(entries)} option entries")
for l in leaks:
    print("LEAK " + l)
PY
grep -q ' option entries' "$tmp/leaks.txt" && [ "$(awk '/option entries/ {print $1}' "$tmp/leaks.txt")" -ge 100 ]
ok=$?  # before the message: its $(...) would set $?
check "option entries scanned: $(head -1 "$tmp/leaks.txt")" $ok
! grep -q '^LEAK' "$tmp/leaks.txt"
ok=$?  # before the message: its $(...) would set $?
check "no parser text, defaults and ranges once and one way$(grep '^LEAK' "$tmp/leaks.txt" | head -5 | sed 's/^/\n  /')" $ok
# The defaults the issue found missing, now shown.
for want in "--gear-ratio.*(default 1)" "--path.*(default /run/odometryd/state.bin)" \
  "--duration.*range \[0, 1e+09\] (default 0)" "--side-wall.*left | right (default left)"; do
  grep -q -- "$want" "$tmp/entries.txt"
  check "help shows /$want/" $?
done

# The checks behind the texts refuse in the same words, naming the option (exit 2).
refuse() {  # refuse NAME EXPECTED CMD...: exit 2, stderr has EXPECTED and no CLI11 wording
  local name=$1 want=$2
  shift 2
  run "$@" >/dev/null 2>"$tmp/err"
  local rc=$?
  [ $rc = 2 ] && grep -qF -- "$want" "$tmp/err" && ! grep -qE 'FAILED|\{|->' "$tmp/err"
  ok=$?  # before the message: its $(...) would set $?
  check "$name: exit 2, '$want' (got $rc: $(head -c 200 "$tmp/err"))" $ok
}
refuse "--side-wall middle" "--side-wall: 'middle' must be left or right" \
  "$ODOMCTL" umbmark record --csv "$tmp/r.csv" --wheelbase 0.34 --side-wall middle
# ... and accept the spellings: --side-wall right reaches the session (its sign diagram).
for wall in left right; do
  run "$ODOMCTL" umbmark record --csv "$tmp/w_$wall.csv" --wheelbase 0.34 --side-wall "$wall" \
    --can-log "$tmp/none.log" --answers /dev/null >"$tmp/wall" 2>&1
  grep -q "^ *$wall wall\$" "$tmp/wall"
  check "--side-wall $wall accepted: the diagram shows the $wall wall" $?
done
refuse "--backend foo" "--backend: 'foo' must be auto or file or nvmem or mtd" \
  "$ODOMCTL" calib show --backend foo
refuse "--duration -1" "odometryd: --duration: -1 is outside [0, 1e+09]" "$ODOMETRYD" --duration -1
refuse "--duration abc" "--duration: 'abc' is not a number" "$ODOMETRYD" --duration abc
refuse "selfcal --late 9" "--late: 9 is outside [0, 4]" "$ODOMCTL" selfcal simulate --late 9
refuse "decode --base-id 2000" "--base-id: 2000 is outside [0, 1024]" \
  "$ODOMCTL" decode --base-id 2000 x.log
# Unknown and missing subcommands (item 6): the word, and the valid ones.
refuse "odomctl bogus" "odomctl: 'bogus' is not a subcommand; the subcommands are: replay, calib," \
  "$ODOMCTL" bogus
refuse "odomctl calib bogus" "odomctl calib: 'bogus' is not a subcommand; the subcommands are: show," \
  "$ODOMCTL" calib bogus
refuse "odomctl" "odomctl: a subcommand is needed: replay, calib, errormodel" "$ODOMCTL"
refuse "odomctl state" "odomctl state: a subcommand is needed: show" "$ODOMCTL" state
refuse "calib export --json" "The following argument was not expected: --json" \
  "$ODOMCTL" calib export --json --store "$tmp/none.bin"

echo "help texts: $pass passed, $fail failed"
[ "$fail" = 0 ]
