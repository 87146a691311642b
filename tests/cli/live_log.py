#!/usr/bin/env python3
"""live_log.py SRC DST CONTROL: a candump -L log being written, from a finished one (issue 35).

SRC is odometryd's --can-log of one simulated square in virtual time. DST is written as a running
daemon writes its log, with wall-clock stamps of now: every 50 ms the node's current pose pair
and a Status frame that does not say stopping (SRC's first one). Each line appended to the file
CONTROL ("drive") makes the robot drive SRC's square: SRC's pose frames, stamped now, appended at
once. Before and after, the robot holds SRC's last pose: a drive's net odometry motion is 0, so
the return error is what the tape answers give. The frames are odometryd's own lines, only their
stamps are new, so no frame layout is written twice. Runs until killed.
"""
import os
import re
import sys
import time

LINE = re.compile(r"\((\d+)\.(\d{6})\) (\S+) ([0-9A-F]{3})#([0-9A-F]*)$")


def main():
    src, dst, control = sys.argv[1:4]
    frames = [LINE.match(ln) for ln in open(src).read().splitlines()]
    frames = [(m.group(3), m.group(4), m.group(5)) for m in frames if m]
    # Ids of the node-1 block at base 0x400: 0x410 PoseX, 0x411 PoseYTheta, 0x414 Status.
    poses = [f for f in frames if f[1] in ("410", "411")]
    status = next(f for f in frames if f[1] == "414")
    hold = poses[-2:]  # the pose the square ends at: a drive moves the odometry 0 net
    out = open(dst, "w")
    drives = 0

    def put(fs):
        now = time.time()
        for iface, fid, data in fs:
            out.write("(%d.%06d) %s %s#%s\n" % (int(now), int(now * 1e6) % 1000000, iface, fid, data))
        out.flush()

    while True:
        n = sum(1 for _ in open(control)) if os.path.exists(control) else 0
        while drives < n:
            drives += 1
            put(poses)
            hold = poses[-2:]
        put(hold + [status])
        time.sleep(0.05)


if __name__ == "__main__":
    main()
