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
  slcan_tool.py serial FILE              the serial counts records of a USART2 capture (below)
  slcan_tool.py pace FILE LINK AFTER     a pty linked at LINK; AFTER seconds later the frames of
                                         FILE (a USART2 capture) written to it one every 10 ms of
                                         the host's clock (the records' own spacing), whole frames
                                         as the UART sent them; then 1 s of quiet and exit
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


def crc16_ccitt_false(data):
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


def cobs_decode(block):
    out, i = bytearray(), 0
    while i < len(block):
        code = block[i]
        if code == 0 or i + code > len(block) + (0 if code > 1 else 0):
            raise ValueError("bad COBS")
        out += block[i + 1:i + code]
        i += code
        if code < 0xFF and i < len(block):
            out.append(0)
    return bytes(out)


def serial_records(path):
    """The serial counts records (issue 37's wire format, written from its spec, not its code):
    COBS frames ending in 0x00; u8 version, u8 flags, u16 seq, u32 time_us, i32 left, i32 right
    little-endian, then CRC-16/CCITT-FALSE of those bytes, little-endian. Version 2 (issue 38):
    u8 version, u8 flags, u16 seq, u32 time_us, u8 wheels_per_side N, u8 wheel_faults, i32
    left[N], i32 right[N], CRC. Each record as (version, flags, seq, time_us, lefts, rights,
    wheel_faults), lefts and rights tuples of N counters."""
    import struct
    recs = []
    for block in open(path, "rb").read().split(b"\0")[:-1]:
        rec = cobs_decode(block)
        body, crc = rec[:-2], struct.unpack("<H", rec[-2:])[0]
        if crc != crc16_ccitt_false(body):
            raise ValueError(f"CRC mismatch in record {len(recs)}")
        if body[0] == 2:
            version, flags, seq, time_us, n, faults = struct.unpack("<BBHIBB", body[:10])
            if len(body) != 10 + 8 * n:
                raise ValueError(f"record {len(recs)}: {len(body)} bytes for {n} wheels a side")
            counts = struct.unpack(f"<{2 * n}i", body[10:])
            recs.append((version, flags, seq, time_us, counts[:n], counts[n:], faults))
        else:
            version, flags, seq, time_us, left, right = struct.unpack("<BBHIii", body[:16])
            recs.append((version, flags, seq, time_us, (left,), (right,), 0))
    return recs


if __name__ == "__main__" and sys.argv[1] == "serial":
    # serial FILE: prints "records first_flags other_flags seq_ok time_steps versions
    # wheels_per_side wheel_faults last_lefts last_rights" (versions: the set of versions seen;
    # wheel_faults: the OR of every record's; the counters comma-separated)
    r = serial_records(sys.argv[2])
    seq_ok = all(r[i][2] == (r[0][2] + i) & 0xFFFF for i in range(len(r)))
    dt = {r[i + 1][3] - r[i][3] for i in range(len(r) - 1)}
    faults = 0
    for x in r:
        faults |= x[6]
    print(len(r), r[0][1], max((x[1] for x in r[1:]), default=0), int(seq_ok),
          str(sorted(dt)).replace(" ", ""), ",".join(str(v) for v in sorted({x[0] for x in r})),
          ",".join(str(v) for v in sorted({len(x[4]) for x in r})), faults,
          ",".join(map(str, r[-1][4])), ",".join(map(str, r[-1][5])))


def pace(path, link, after):
    """A USART2 capture replayed on a pty at the firmware's record rate (see the top)."""
    import os
    import termios
    import time
    import tty
    master, slave = os.openpty()
    tty.setraw(slave, termios.TCSANOW)
    tmp = link + ".new"
    if os.path.lexists(tmp):
        os.unlink(tmp)
    os.symlink(os.ttyname(slave), tmp)
    os.rename(tmp, link)
    frames_ = [b + b"\0" for b in open(path, "rb").read().split(b"\0")[:-1]]
    t0 = time.monotonic() + after
    for i, f in enumerate(frames_):
        time.sleep(max(0.0, t0 + 0.01 * i - time.monotonic()))
        os.write(master, f)
    time.sleep(1.0)
    print(f"pace: {len(frames_)} frames in {time.monotonic() - t0:.2f} s", file=sys.stderr)


if __name__ == "__main__" and sys.argv[1] == "pace":
    pace(sys.argv[2], sys.argv[3], float(sys.argv[4]))
