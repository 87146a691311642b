#!/usr/bin/env bash
# odomctl in a real terminal (issue 20): `umbmark record` typed into a tmux pane (send-keys,
# capture-pane), and `umbmark simulate`'s progress as one line updated in place.
# Skipped (exit 77) without tmux.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp
if ! command -v tmux >/dev/null; then
  echo "SKIP: tmux is not installed (tools/setup.sh installs it with the test packages)"
  exit 77
fi
sock="odo-tty-$$"
tm() { tmux -L "$sock" -f /dev/null "$@"; }
trap 'tm kill-server 2>/dev/null; rm -rf "$tmp"' EXIT
# A session that outlives the test's own: tmux exits once its last session ends, and a client
# started meanwhile can reach the exiting server and fail; one server serves the whole script.
tm new-session -d -s keep "sleep 600"
# wait_pane TEXT: until the visible pane holds TEXT (at most 20 s).
pane_has() { tm capture-pane -p -t t >"$tmp/pane" 2>/dev/null; grep -q -- "$1" "$tmp/pane"; }
wait_pane() {
  poll 20 pane_has "$1" && return 0
  echo "timeout waiting for '$1' in the pane:"; cat "$tmp/pane"; return 1
}
# type TEXT: the keys of TEXT and Enter.
type_() { tm send-keys -t t -l -- "$1"; tm send-keys -t t Enter; }

# The daemon's log being written (lib.sh start_live_log): a line in $tmp/drive drives the
# square (the odometry back where it started).
start_live_log "$tmp/pose.log" "$tmp/drive"
trap 'kill $relay 2>/dev/null; tm kill-server 2>/dev/null; rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
tm new-session -d -s t -x 120 -y 60 \
  "${CROSS_EMULATOR:-} $ODOMCTL umbmark record --csv runs.csv --can-log pose.log --wheelbase 0.34 \
   --side-wall right 2>rec.err; echo exit=\$?; sleep 30"
wait_pane "reference point to the back wall" && type_ 500 &&
  wait_pane "to the right wall" && type_ 300 && wait_pane "start pose" && type_ "" &&
  wait_pane "has stopped" && echo drive >>"$tmp/drive" && sleep 0.2 && type_ ""
check "record prompts in a terminal" $?
grep -q "right wall" "$tmp/pane" && grep -q "y_abs = right(end) - right(start)" "$tmp/pane" &&
  grep -q "Run 1 of 10: cw" "$tmp/pane" && grep -q "odometry at start: x 0.0003 m" "$tmp/pane"
check "record shows the sign diagram for a right wall and the start pose" $?
# With a right wall the back wall's label is above the back wall (||), the right wall's below
# the bottom wall (issue 35: it sat under the right wall's label).
grep -A1 "^  back wall$" "$tmp/pane" | tail -1 | grep -q "^  ||    o---> x" &&
  [ "$(grep -A2 "^  ++====" "$tmp/pane" | grep -c "back wall")" = 0 ]
check "record: the back wall's label at the back wall for --side-wall right" $?
# A typo is asked again on a terminal, and so are metres where millimetres are asked; then the
# end tape: 12 mm further from the back wall, 3 mm further from the right wall (y_abs = +3 mm),
# heading not measured.
wait_pane "tape at end: reference point to the back wall" && type_ "5l2" &&
  wait_pane "'5l2' is not a number" && type_ 0.512 && wait_pane "metres typed? type millimetres (0.512 m = 512 mm); again." &&
  type_ 512 && wait_pane "tape at end: reference point to the right" &&
  type_ 303 && wait_pane "heading change" && type_ "" && wait_pane "saved in runs.csv (1 of 10)"
check "record: a typo is asked again, the run is saved" $?
# The running centre of gravity is printed after the "saved" line: wait for the next run's
# heading, which comes after both (a capture between the two lines failed under qemu-arm once).
wait_pane "Run 2 of 10" &&
  grep -q "return error (absolute - odometry): ex +12.0 mm, ey +3.0 mm" "$tmp/pane" &&
  grep -q "cw  n 1, centre of gravity x +12.0 mm, y +3.0 mm" "$tmp/pane"
check "record: return error and running centre of gravity on screen" $?
# Interrupted with Ctrl-C in the next run: it says what Ctrl-D says (issue 35: it left without a
# word), the saved run stays, the rerun resumes at run 2.
tm send-keys -t t C-c && wait_text "$tmp/rec.err" "stopped;" &&
  [ "$(cat "$tmp/rec.err")" = "odomctl umbmark record: stopped; 1 runs saved in runs.csv: the same command resumes" ] &&
  grep -q "^cw,0.0120,0.0030,,0$" "$tmp/runs.csv" && [ "$(wc -l <"$tmp/runs.csv")" = 2 ]
rc_=$?
check "record: Ctrl-C says what Ctrl-D says and keeps the saved run: $(cat "$tmp/rec.err") $(tr '\n' '|' <"$tmp/runs.csv")" $rc_
tm kill-session -t t 2>/dev/null
# Ctrl-D at the same point: the same words.
tm new-session -d -s t -x 120 -y 60 \
  "${CROSS_EMULATOR:-} $ODOMCTL umbmark record --csv runs.csv --can-log pose.log --wheelbase 0.34 2>recd.err; sleep 30"
wait_pane "Run 2 of 10: cw" && wait_pane "reference point to the back wall" && tm send-keys -t t C-d &&
  wait_text "$tmp/recd.err" "stopped;" && cmp -s "$tmp/rec.err" "$tmp/recd.err"
rc_=$?
check "record: Ctrl-D says the same: $(cat "$tmp/recd.err")" $rc_
tm kill-session -t t 2>/dev/null
tm new-session -d -s t -x 120 -y 60 \
  "${CROSS_EMULATOR:-} $ODOMCTL umbmark record --csv runs.csv --can-log pose.log --wheelbase 0.34; sleep 30"
# "Run 2" is printed after the header and the sign diagram: wait for it, then read the header.
wait_pane "Run 2 of 10: cw" && grep -q "1 already in runs.csv" "$tmp/pane"
check "record resumes at run 2 in a terminal" $?
tm kill-session -t t 2>/dev/null

# simulate's progress: one line rewritten in place (\r), raw bytes of the pane's output. The
# pane waits on a tmux channel until the pipe is attached (a fixed sleep raced it), and the
# bytes are counted once `cat` has written the final line too (the pane shows it first).
tm new-session -d -s t -x 120 -y 20 "tmux wait-for piped; ${CROSS_EMULATOR:-} $ODOMCTL umbmark simulate --runs 10 --passes 2 >/dev/null; echo done; sleep 30"
tm pipe-pane -o -t t "cat >$tmp/raw" && tm wait-for -S piped
wait_pane "^done" && wait_text "$tmp/raw" "60 squares driven"
updates=$(grep -a -o "/60 squares, [0-9]* s left" "$tmp/raw" | wc -l)
lines=$(grep -a -c "squares, " "$tmp/raw")
[ "$updates" -ge 2 ] && [ "$lines" -le 1 ] && grep -q "umbmark simulate: 60 squares driven" "$tmp/pane" &&
  ! grep -q "squares, .* s left" "$tmp/pane"
check "simulate on a terminal: $updates updates on one line ($lines line), cleared at the end" $?

echo "cli_umbmark_tty: $pass passed, $fail failed"
[ $fail = 0 ]
