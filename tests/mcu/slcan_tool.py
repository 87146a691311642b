#!/usr/bin/env python3
"""SLCAN helpers for the microcontroller tests (tests/mcu): no project code, only the framing.

  slcan_tool.py candump IN.txt OUT.log   SLCAN lines ('\\r'-separated, '#'-lines skipped) as a
                                         candump -L log (interface mcu0, stamps 0.01 s apart) for
                                         `odomctl decode`
  slcan_tool.py setpose ELF X Y THETA    runs the firmware in QEMU with USART1 on stdio; after 100
                                         pose frames sends set-pose (x, y [m], theta [rad]; the
                                         protocol's DBC layout: int24 mm, int24 mm, int16 1e-4 rad)
                                         as SLCAN to node 1 (id 0x418), prints the frames after it
                                         as candump -L lines and the '#'-lines on stderr
"""
import subprocess
import sys


def frames(text):
    """(id, data hex) of each t/T line."""
    for line in text.split("\r"):
        line = line.strip("\n")
        if line[:1] == "t" and len(line) >= 5:
            n = int(line[4], 16)
            yield int(line[1:4], 16), line[5:5 + 2 * n], False
        elif line[:1] == "T" and len(line) >= 10:
            n = int(line[9], 16)
            yield int(line[1:9], 16), line[10:10 + 2 * n], True


def candump(src, dst):
    with open(src, encoding="ascii", errors="replace", newline="") as f, open(dst, "w") as o:
        for i, (fid, data, ext) in enumerate(frames(f.read())):
            ids = f"{fid:08X}" if ext else f"{fid:03X}"
            o.write(f"({i // 100}.{(i % 100) * 10000:06d}) mcu0 {ids}#{data}\n")


def le(v, nbytes):
    return (v & ((1 << (8 * nbytes)) - 1)).to_bytes(nbytes, "little")


def setpose(elf, x, y, theta):
    cmd = ["qemu-system-arm", "-M", "netduinoplus2", "-display", "none", "-monitor", "none",
           "-serial", "stdio", "-kernel", elf, "-icount", "shift=0,sleep=off",
           "-semihosting-config", "enable=on,target=native,arg=odo,arg=--duration,arg=20"]
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    data = le(round(x * 1000), 3) + le(round(y * 1000), 3) + le(round(theta * 1e4), 2)
    line = b"t4188" + data.hex().upper().encode() + b"\r"
    buf, seen, sent, i = b"", 0, False, 0
    while True:
        c = p.stdout.read(1)
        if not c:
            break
        if c != b"\r":
            buf += c
            continue
        s = buf.decode("ascii", "replace").strip("\n")
        buf = b""
        if s.startswith("#"):
            print(s, file=sys.stderr)
        elif s.startswith("t"):
            seen += 1
            if sent:
                for fid, d, _ in frames(s + "\r"):
                    print(f"({i // 100}.{(i % 100) * 10000:06d}) mcu0 {fid:03X}#{d}")
                    i += 1
            if seen == 100 and not sent:
                p.stdin.write(line)
                p.stdin.flush()
                sent = True
    return p.wait()


if __name__ == "__main__":
    if sys.argv[1] == "candump":
        candump(sys.argv[2], sys.argv[3])
    elif sys.argv[1] == "setpose":
        sys.exit(setpose(sys.argv[2], *map(float, sys.argv[3:6])))
