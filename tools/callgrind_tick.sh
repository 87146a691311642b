#!/usr/bin/env bash
# callgrind_tick.sh - instructions per loop tick and per stage, counted by valgrind's callgrind
# (stable on noisy shared machines, unlike nanoseconds).
#   tools/callgrind_tick.sh [N]      N ticks per run (default 100000)
# Builds tests/bench/tick_driver with the `bench` preset (Release, -O2 -DNDEBUG), runs it twice
# under callgrind with collection only inside OdometryLoop::tick():
#   sim       encoder = the simulated robot (its exact-arc motion model is most of the cost)
#   counting  encoder = a counter-register read (the firmware's own cost of a tick)
#   gyro      sim plus the consumer gyro and the gyrodometry fusion (issue 16)
#   fwgyro    counting plus a gyro sample read from memory and the same fusion: the firmware's
#             own cost of a tick with the gyro (the simulated robot and gyro excluded)
#   persist   counting plus the state persister (issue 17): its cost is the difference
#   record    sim read through the self-calibration recorder (issue 18): the difference to sim
# and prints instructions per tick for the full tick and for every function it calls (inclusive).
# Exit 1 when a target is missed: pose update <= 330, full tick <= 1000 instructions (issue 9);
# full tick with the gyro <= 1100 (issue 16); the persister's share <= 50 (issue 17). The
# recorder's share and the firmware's own tick with the gyro are reported (no target: issue 16's
# target is the gyro run's, simulated robot and gyro included).
# Rerun after merging new stages (covariance, CAN frame encoding): they show up as new rows.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-100000}
if ! [[ $n =~ ^[1-9][0-9]*$ ]]; then
  echo "callgrind_tick.sh: N = '$n' must be a positive integer" >&2
  exit 2
fi
command -v valgrind >/dev/null || { echo "callgrind_tick.sh: valgrind missing (tools/setup.sh --tests)" >&2; exit 2; }
cmake --preset bench >/dev/null
cmake --build build/bench -j"${ODO_JOBS:-2}" --target tick_driver >/dev/null
drv=build/bench/tests/bench/tick_driver
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
status=0
echo "callgrind: $n ticks at 1 kHz, $(g++ --version | head -1), preset bench (-O2 -DNDEBUG), $(uname -m)"
for mode in sim counting gyro fwgyro persist record; do
  args=("$mode" "$n")
  [[ $mode == persist ]] && args=(counting "$n" persist)
  [[ $mode == record ]] && args=(sim "$n" record)
  valgrind --tool=callgrind --callgrind-out-file="$tmp/$mode.out" \
    --toggle-collect='odo::loop::OdometryLoop::tick()' "$drv" "${args[@]}" >"$tmp/$mode.log" 2>&1
  callgrind_annotate --inclusive=yes --threshold=100 "$tmp/$mode.out" >"$tmp/$mode.txt" 2>/dev/null
  echo
  echo "encoder = $mode: instructions per tick (inclusive; rows below the tick are its callees)"
  # Rows from the tick down; libc start-up frames above it are the same total.
  awk -v n="$n" '
    /OdometryLoop::tick\(\)/ { go = 1 }
    go && $1 ~ /^[0-9,]+$/ {
      ir = $1; gsub(",", "", ir)
      fn = $0; sub(/^[^:]*:/, "", fn); sub(/ \[.*$/, "", fn)
      if (ir / n >= 0.5) printf "  %10.1f  %s\n", ir / n, fn
    }' "$tmp/$mode.txt" | head -25 | tee "$tmp/$mode.rows"
  tick=$(awk '/OdometryLoop::tick\(\)/ { print $1; exit }' "$tmp/$mode.rows")
  if [[ $mode == persist ]]; then
    share=$(awk -v t="$tick" -v c="$counting_tick" 'BEGIN { printf "%.1f", t - c }')
    echo "  => full tick $tick with the persister: its share $share (target <= 50)"
    awk -v s="$share" 'BEGIN { exit !(s <= 50) }' || status=1
    continue
  fi
  if [[ $mode == record ]]; then
    share=$(awk -v t="$tick" -v s="$sim_tick" 'BEGIN { printf "%.1f", t - s }')
    echo "  => full tick $tick with the recorder: its share $share"
    continue
  fi
  [[ $mode == counting ]] && counting_tick=$tick
  [[ $mode == sim ]] && sim_tick=$tick
  if [[ $mode == gyro ]]; then
    echo "  => full tick $tick with the gyro (target <= 1100)"
    awk -v t="$tick" 'BEGIN { exit !(t <= 1100) }' || status=1
    continue
  fi
  if [[ $mode == fwgyro ]]; then
    echo "  => full tick $tick with the gyro, firmware only (the counting encoder and gyro)"
    continue
  fi
  pose=$(awk '/odo::Odometry::update/ { print $1; exit }' "$tmp/$mode.rows")
  echo "  => full tick $tick (target <= 1000), pose update $pose (target <= 330)"
  awk -v t="$tick" -v p="$pose" 'BEGIN { exit !(t <= 1000 && p <= 330) }' || status=1
done
exit $status
