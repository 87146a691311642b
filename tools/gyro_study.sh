#!/usr/bin/env bash
# gyro_study.sh - the extended UMBmark with and without the gyro fusion over many seeds (issue 16).
#   tools/gyro_study.sh [--odomctl PATH] [--seeds N] [--noise paper|none] [--gyro consumer|industrial]
# Runs `odomctl umbmark simulate --bumps --noise NOISE --gyro CLASS --seed S --json` for
# S = 1..N (default 20, paper, consumer) and prints one row per seed and the median, minimum and
# maximum of: eps_theta,nonsys plain / fused and their ratio, the uncalibrated plain bump runs'
# mean return error against the calibrated fused one and their ratio, calibrated plain against
# fused on the course without bumps (the smooth-floor cost), and the fusion's events.
set -euo pipefail
cd "$(dirname "$0")/.."
odomctl=build/odomctl/odomctl seeds=20 noise=paper gyro=consumer
while [ $# -gt 0 ]; do
  case $1 in
    --odomctl) odomctl=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --noise) noise=$2; shift 2 ;;
    --gyro) gyro=$2; shift 2 ;;
    *) echo "gyro_study.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[[ $seeds =~ ^[1-9][0-9]*$ ]] || { echo "gyro_study.sh: --seeds '$seeds' must be a positive integer" >&2; exit 2; }
[ -x "$odomctl" ] || { echo "gyro_study.sh: $odomctl is not an executable (build first, or --odomctl)" >&2; exit 2; }
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
for s in $(seq 1 "$seeds"); do
  "$odomctl" umbmark simulate --bumps --noise "$noise" --gyro "$gyro" --seed "$s" --json \
    >"$out/$s.json" 2>/dev/null
done
echo "odomctl umbmark simulate --bumps --noise $noise --gyro $gyro --seed 1..$seeds --json"
python3 - "$out" "$seeds" <<'PY'
import json, statistics, sys
d, n = sys.argv[1], int(sys.argv[2])
rows = []
for s in range(1, n + 1):
    g = json.load(open(f"{d}/{s}.json"))["gyro"]
    rows.append((s, g["eps_theta_nonsys_plain"], g["eps_theta_nonsys_fused"],
                 g["eps_theta_nonsys_plain"] / g["eps_theta_nonsys_fused"],
                 g["uncal_plain_bumps"] * 1e3, g["cal_fused_bumps"] * 1e3,
                 g["uncal_plain_bumps"] / g["cal_fused_bumps"],
                 g["cal_plain_smooth"] * 1e3, g["cal_fused_smooth"] * 1e3, g["events"]))
head = ("seed", "eps plain [rad]", "eps fused [rad]", "ratio", "uncal plain bumps [mm]",
        "cal fused bumps [mm]", "ratio", "cal plain smooth [mm]", "cal fused smooth [mm]",
        "events")
print("| " + " | ".join(head) + " |")
print("|" + "---|" * len(head))
fmt = lambda r: [str(r[0]), f"{r[1]:.4f}", f"{r[2]:.4f}", f"{r[3]:.1f}", f"{r[4]:.1f}",
                 f"{r[5]:.1f}", f"{r[6]:.1f}", f"{r[7]:.2f}", f"{r[8]:.2f}", str(r[9])]
for r in rows:
    print("| " + " | ".join(fmt(r)) + " |")
for name, f in (("median", statistics.median), ("min", min), ("max", max)):
    cols = [f([r[i] for r in rows]) for i in range(1, 10)]
    print("| " + name + " | " + " | ".join(fmt([0] + cols)[1:]) + " |")
PY
