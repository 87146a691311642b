#!/usr/bin/env python3
# spin_gyro_log.py OUT: a count log with a gyro_z column (test_cli.sh, replay --config): the
# shipped config's robot (0.15 m wheels, 2048 x 16 counts, b = 0.34 m) at 100 Hz.
# A spin log at 100 Hz: 1.5 s still, then turns on the spot (wheels at -+w_wheel) and stops,
# the gyro reading the wheels' own yaw rate with no delay and no noise beyond its bias.
import math, sys
D, CE, N, B = 0.15, 2048, 16, 0.34
mpc = math.pi * D / (N * CE)
rate = 100.0
dt = 1.0 / rate
bias = 0.001
rows = ["t,left,right,gyro_z"]
l = r = 0.0
t = 0.0
segs = [(1.5, 0.0)] + [(1.0, 0.5), (0.5, 0.0), (1.0, -0.5), (0.5, 0.0)] * 4  # (s, yaw rate)
prev_l = prev_r = 0
i = 0
for dur, w in segs:
    for _ in range(int(round(dur * rate))):
        i += 1
        t = i * dt
        v_wheel = w * B / 2.0
        l -= v_wheel * dt / mpc
        r += v_wheel * dt / mpc
        li, ri = int(math.floor(l)), int(math.floor(r))
        # the yaw rate the counts show over this tick (the gyro has no delay)
        g = ((ri - prev_r) - (li - prev_l)) * mpc / B / dt + bias
        prev_l, prev_r = li, ri
        rows.append(f"{t:.6f},{li},{ri},{g:.9f}")
rows.insert(1, "0.000000,0,0,%.9f" % bias)
open(sys.argv[1], "w").write("\n".join(rows) + "\n")
