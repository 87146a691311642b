#!/usr/bin/env bash
# ros2_latency.sh - latency from the encoder sample to a DDS subscriber's receipt on the loopback
# (issue 19), A/B: runs odometryd (simulated robot, 1 kHz loop, SCHED_FIFO 80, [ros2] on lo) with
# each variant in turn, REPS times alternating (A B A B ...), beside a receiver process at
# SCHED_FIFO 10, and prints one table row per run with the load average at its start and the
# share of time all CPUs were idle during it (/proc/stat; busy CPUs hide the idle wake-ups).
#   tools/ros2_latency.sh [--seconds S] [--reps N] [--rate HZ] [--odometryd PATH] [--peer PATH]
#                         [--variant 'NAME:TOML LINES'] ...
# A variant is a name, a colon and extra [ros2] lines ('\n' separates lines), e.g.
#   --variant 'off:' --variant 'spin300:spin_us = 300'
# and NAME@PATH runs the odometryd at PATH for that variant (A/B of two builds).
# A name ending in "+pmqos" runs odometryd with [realtime] cpu_latency_us = 0: it holds
# /dev/cpu_dma_latency at 0 while it runs (idle CPUs poll instead of halting, as under
# cyclictest; needs root).
# Columns: receiver n, p50, p99, max [ms]; the publisher's share (sample to the return of the
# odom write, to 10 us); odom published / expected; odometryd CPU (user+sys,
# /usr/bin/time) per published message [us]; the bridge's polls (spin_us): mean wait, how many
# found the sample already there (the thread woke late); the looks at a due tick that had not
# come yet (the loop woke late) and the publishes of an older sample instead.
# Defaults: 15 s, 3 reps, 100 Hz, build/default binaries, the Fast DDS peer.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=15 reps=3 rate=100 bin=build/default/firmware/odometryd
peer=build/default/tests/ros2/ros2_fastdds_peer
variants=()
while (($#)); do
  case $1 in
    --seconds) secs=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    --rate) rate=$2; shift 2 ;;
    --odometryd) bin=$2; shift 2 ;;
    --peer) peer=$2; shift 2 ;;
    --variant) variants+=("$2"); shift 2 ;;
    *) echo "ros2_latency.sh: unknown option '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
for v in "$secs" "$reps" "$rate"; do
  [[ $v =~ ^[0-9]+$ ]] || { echo "ros2_latency.sh: '$v' must be a non-negative integer" >&2; exit 2; }
done
((${#variants[@]})) || variants=('default:')
for f in "$bin" "$peer"; do
  [ -x "$f" ] || { echo "ros2_latency.sh: $f missing (cmake --build build/default --target odometryd ros2_fastdds_peer ros2_cyclone_peer)" >&2; exit 2; }
done
tmp=$(mktemp -d)
peer_pid=
cleanup() {
  [ -n "$peer_pid" ] && kill "$peer_pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
. tools/ros2_loopback.sh  # ros2_loopback_toml, CYCLONEDDS_URI
domain=$((100 + $$ % 120))

echo "ros2_latency: $secs s per run, $reps reps, [ros2] rate_hz = $rate, receiver $(basename "$peer") at SCHED_FIFO 10"
echo "              $(uname -r), cpuidle driver $(cat /sys/devices/system/cpu/cpuidle/current_driver 2>/dev/null || echo none), $(nproc) CPUs"
printf '| run | variant | load avg (1 min) | CPUs idle [%%] | n | p50 [ms] | p99 [ms] | max [ms] | write age p50 / p99 [ms] | published / expected | CPU / msg [us] | spin wait mean [us] | polls late | due waits / stale |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
run=0
for ((r = 1; r <= reps; r++)); do
  for v in "${variants[@]}"; do
    name=${v%%:*} extra=${v#*:} vbin=$bin
    if [[ $name == *@* ]]; then vbin=${name#*@} name=${name%%@*}; fi
    run=$((run + 1)) qos=-1
    if [[ $name == *+pmqos ]]; then qos=0; fi
    cat >"$tmp/lat.toml" <<TOML
[loop]
rate_hz = 1000
status_period = 0
[realtime]
priority = 80
lock_memory = true
cpu_latency_us = $qos
[calibration]
store = ""
TOML
    ros2_loopback_toml "$domain" "$rate" >>"$tmp/lat.toml"
    printf '%b\n' "$extra" >>"$tmp/lat.toml"
    load=$(cut -d' ' -f1 /proc/loadavg)
    stat0=$(head -1 /proc/stat)
    chrt -f 10 "$peer" --domain "$domain" --odom 1 --idle 2 --quiet --skip 50 --timeout "$((secs + 30))" >"$tmp/peer.out" 2>&1 &
    peer_pid=$!
    /usr/bin/time -f '%U %S' -o "$tmp/time" "$vbin" --config "$tmp/lat.toml" --duration "$secs" --json --quiet >"$tmp/d.json" 2>"$tmp/d.err" || {
      echo "ros2_latency.sh: odometryd failed:" >&2; cat "$tmp/d.err" >&2; exit 1; }
    wait "$peer_pid" || { echo "ros2_latency.sh: the peer failed:" >&2; cat "$tmp/peer.out" >&2; exit 1; }
    peer_pid=
    stat1=$(head -1 /proc/stat)
    python3 - "$tmp/peer.out" "$tmp/d.json" "$tmp/time" "$run" "$name" "$load" "$secs" "$rate" "$stat0" "$stat1" <<'PY'
import json, re, sys
peer, dj, tm, run, name, load, secs, rate, st0, st1 = sys.argv[1:11]
# Idle share of all CPUs during the run (/proc/stat: idle + iowait of all jiffies).
d = [b - a for a, b in zip(map(int, st0.split()[1:]), map(int, st1.split()[1:]))]
idle = 100.0 * (d[3] + d[4]) / max(1, sum(d))
m = dict(re.findall(r"(\w+)=([\d.]+)", next(l for l in open(peer) if l.startswith("latency"))))
r = json.load(open(dj))["ros2"]
u, s = map(float, open(tm).read().split()[-2:])
pub = r["odom_published"]
spins = r.get("spin_count", 0)
wait = f"{r['spin_wait_sum'] * 1e6 / spins:.0f}" if spins else "-"
print(f"| {run} | {name} | {load} | {idle:.0f} | {m['n']} | {float(m['p50_us']) / 1e3:.2f} | "
      f"{float(m['p99_us']) / 1e3:.2f} | {float(m['max_us']) / 1e3:.2f} | "
      f"{r['write_age_p50'] * 1e3:.2f} / {r['write_age_p99'] * 1e3:.2f} | "
      f"{pub} / {int(float(secs) * float(rate))} | {(u + s) * 1e6 / max(pub, 1):.0f} | {wait} | "
      f"{r.get('spin_late', '-')} | {r.get('due_waits', '-')} / {r.get('stale_published', '-')} |")
PY
  done
done
