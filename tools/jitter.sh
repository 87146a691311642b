#!/usr/bin/env bash
# jitter.sh - the loop's wake-up latency against cyclictest's, same rate, priority and CPU, run
# side by side, idle and with load on the other core. The figure is the ratio
# loop / cyclictest of p99 and max wake-up latency (issue 9 target: <= 1.5 idle and loaded).
#   tools/jitter.sh [--seconds S] [--priority P] [--cpu C] [--load-cpu L] [--odometryd PATH]
#                   [--ros2 PEER [--ros2-rate HZ] [--ros2-spin US]]
# Defaults: 60 s, priority 80, loop and cyclictest on CPU 0, load (stress-ng --cpu 1, or a
# shell busy loop when stress-ng is missing) on CPU 1. Needs root or CAP_SYS_NICE + CAP_IPC_LOCK
# (without them both run unprivileged and the script says so). Packages: rt-tests, stress-ng.
# The loop is odometryd (simulated robot, CLOCK_MONOTONIC, 1 kHz); default binary: the
# `release` preset's build (built here when missing).
# --ros2 PEER: the same with the ROS 2 output on ([ros2] on lo, unicast, --ros2-rate Hz, default
# 1000: every tick) and PEER (tests/ros2's ros2_cyclone_peer or ros2_fastdds_peer) receiving it,
# so that the loop runs beside a busy DDS thread (issue 19: wake-up latency with and without DDS);
# --ros2-spin US sets [ros2] spin_us (the publish thread's early wake-up and bounded poll).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=60 prio=80 cpu=0 load_cpu=1 bin=build/release/firmware/odometryd peer= ros2_rate=1000 ros2_spin=0
while (($#)); do
  case $1 in
    --seconds) secs=$2; shift 2 ;;
    --priority) prio=$2; shift 2 ;;
    --cpu) cpu=$2; shift 2 ;;
    --load-cpu) load_cpu=$2; shift 2 ;;
    --odometryd) bin=$2; shift 2 ;;
    --ros2) peer=$2; shift 2 ;;
    --ros2-rate) ros2_rate=$2; shift 2 ;;
    --ros2-spin) ros2_spin=$2; shift 2 ;;
    *) echo "jitter.sh: unknown option '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
for v in "$secs" "$prio" "$cpu" "$load_cpu" "$ros2_rate" "$ros2_spin"; do
  [[ $v =~ ^[0-9]+$ ]] || { echo "jitter.sh: '$v' must be a non-negative integer" >&2; exit 2; }
done
((prio >= 1 && prio <= 99)) || { echo "jitter.sh: --priority $prio outside 1..99" >&2; exit 2; }
command -v cyclictest >/dev/null || { echo "jitter.sh: cyclictest missing (apt-get install rt-tests)" >&2; exit 2; }
if [ ! -x "$bin" ]; then
  cmake --preset release >/dev/null && cmake --build build/release -j"${ODO_JOBS:-2}" --target odometryd >/dev/null
fi
tmp=$(mktemp -d)
load_pid=
peer_pid=
cleanup() {
  [ -n "$load_pid" ] && kill "$load_pid" 2>/dev/null
  [ -n "$peer_pid" ] && kill "$peer_pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT

cat >"$tmp/jitter.toml" <<TOML
[loop]
rate_hz = 1000
status_period = 0
[realtime]
priority = $prio
lock_memory = true
cpu = $cpu
TOML
domain=$((100 + $$ % 120))
if [ -n "$peer" ]; then
  . tools/ros2_loopback.sh  # ros2_loopback_toml, CYCLONEDDS_URI
  { ros2_loopback_toml "$domain" "$ros2_rate"; echo "spin_us = $ros2_spin"; } >>"$tmp/jitter.toml"
fi
# start_peer: the DDS receiver beside the loop (--ros2), until odometryd stopped publishing.
start_peer() {
  "$peer" --domain "$domain" --odom 1 --idle 2 --quiet --skip 100 --timeout "$((secs + 30))" >"$tmp/peer.out" 2>&1 &
  peer_pid=$!
}

start_load() {
  if command -v stress-ng >/dev/null; then
    stress-ng --cpu 1 --taskset "$load_cpu" --timeout "$((secs + 10))s" --quiet &
  else
    taskset -c "$load_cpu" bash -c 'while :; do :; done' &
  fi
  load_pid=$!
}

# p99 and max [us] from cyclictest's histogram file ("usec count" rows, 1 us bins).
ct_figures() {
  python3 - "$1" <<'PY'
import sys
rows = []
mx = None
for line in open(sys.argv[1]):
    if line.startswith("# Max Latencies:"):
        mx = int(line.split(":")[1].split()[0])
    elif line.strip() and not line.startswith("#"):
        us, n = line.split()[:2]
        rows.append((int(us), int(n)))
total = sum(n for _, n in rows)
rank = -(-99 * total // 100)  # ceil(0.99 * total)
seen = 0
for us, n in rows:
    seen += n
    if seen >= rank:
        print(us, mx, total)
        break
PY
}

echo "jitter: $secs s per condition, 1 kHz, SCHED_FIFO $prio, CPU $cpu; load on CPU $load_cpu;"
[ -z "$peer" ] || echo "        ROS 2 output on at $ros2_rate Hz (spin_us $ros2_spin), received by $(basename "$peer") on lo"
echo "        $(uname -r), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) CPUs"
printf '| condition | loop p99 [us] | cyclictest p99 [us] | p99 ratio | loop max [us] | cyclictest max [us] | max ratio | loop ticks | cyclictest loops |\n'
printf '|---|---|---|---|---|---|---|---|---|\n'
for cond in idle loaded; do
  load_pid=
  [ "$cond" = loaded ] && start_load
  [ -z "$peer" ] || start_peer
  sleep 1
  cyclictest -m -q -p "$prio" -i 1000 -a "$cpu" -D "${secs}s" -h 20000 \
    --histfile="$tmp/ct.hist" >"$tmp/ct.out" 2>&1 &
  ct=$!
  "$bin" --config "$tmp/jitter.toml" --duration "$secs" --json --quiet >"$tmp/loop.json" 2>"$tmp/loop.err" || {
    echo "jitter.sh: odometryd failed:" >&2; cat "$tmp/loop.err" >&2; exit 1; }
  wait "$ct" || { echo "jitter.sh: cyclictest failed:" >&2; cat "$tmp/ct.out" >&2; exit 1; }
  if [ -n "$load_pid" ]; then kill "$load_pid" 2>/dev/null || true; wait "$load_pid" 2>/dev/null || true; load_pid=; fi
  if [ -n "$peer_pid" ]; then
    wait "$peer_pid" || { echo "jitter.sh: the ROS 2 peer failed:" >&2; cat "$tmp/peer.out" >&2; exit 1; }
    peer_pid=
    echo "($cond) peer: $(grep latency "$tmp/peer.out"); odometryd: $(python3 -c 'import json,sys; r=json.load(open(sys.argv[1]))["ros2"]; print("odom_published", r["odom_published"])' "$tmp/loop.json")" >>"$tmp/peer.summary"
  fi
  grep -q "NOT APPLIED" "$tmp/loop.err" && { echo "jitter.sh: warning: real-time set-up incomplete:" >&2; grep "NOT APPLIED" "$tmp/loop.err" >&2; }
  read -r ct_p99 ct_max ct_n < <(ct_figures "$tmp/ct.hist")
  python3 - "$tmp/loop.json" "$cond" "$ct_p99" "$ct_max" "$ct_n" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
t = j["timing"]["wakeup_latency"]
lp, lm = t["p99"] * 1e6, t["max"] * 1e6
cp, cm = float(sys.argv[3]), float(sys.argv[4])
ratio = lambda a, b: f"{a / b:.2f}" if b > 0 else "n/a"
print(f"| {sys.argv[2]} | {lp:.1f} | {cp:.0f} | {ratio(lp, cp)} | {lm:.1f} | {cm:.0f} | {ratio(lm, cm)} | {j['ticks']} | {sys.argv[5]} |")
PY
done
[ ! -s "$tmp/peer.summary" ] || cat "$tmp/peer.summary"
