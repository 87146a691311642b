#!/usr/bin/env python3
"""serial_relay: stands between a serial counts source (the microcontroller firmware in QEMU,
its USART2 on a pty) and odometryd, on kernel pseudo-terminals (issue 37).

It reads the diffodom stream from --source (a path, re-opened whenever it vanishes: the test
restarts QEMU for a controller reset and re-points the link), decodes every record with its own
COBS and CRC-16/CCITT-FALSE code written from the format's description in README "Serial counts
stream" (not the firmware's codec), and forwards whole frames to a pty it makes and links at
--link, at most one per --spacing seconds. Every record it forwards is written to --log as
`t,left,right` with the counters continued across a controller reset (a record flagged booted
after one that was not: the new counts are added to the last ones), which is what `odomctl
replay` needs to give the pose odometryd must have. Faults: --garbage-at T (48 bytes of noise
to odometryd), --unplug-at T (its pty closed, a new one under the same link after --unplug-for
seconds; nothing forwarded until --rearm seconds later, so nothing is logged that odometryd
could not read). --start-after: forwarding begins then (odometryd has the pty open).
"""
import argparse
import binascii
import os
import random
import select
import struct
import sys
import termios
import time
import tty


def cobs_decode(block):
    out = bytearray()
    i = 0
    while i < len(block):
        code = block[i]
        if code == 0 or i + code > len(block):  # a code running past the end
            return None
        out += block[i + 1:i + code]
        i += code
        if code != 0xFF and i < len(block):
            out.append(0)
    return bytes(out)


def decode(frame):
    """frame: the COBS block without its 0x00; the record's fields or None."""
    raw = cobs_decode(frame)
    if raw is None or len(raw) != 18:
        return None
    if binascii.crc_hqx(raw[:16], 0xFFFF) != struct.unpack_from("<H", raw, 16)[0]:
        return None
    version, flags, seq, time_us, left, right = struct.unpack_from("<BBHIii", raw)
    return None if version != 1 else (flags, seq, time_us, left, right)


def make_pty(link):
    master, slave = os.openpty()
    tty.setraw(slave, termios.TCSANOW)
    name = os.ttyname(slave)
    tmp = link + ".new"
    if os.path.lexists(tmp):
        os.unlink(tmp)
    os.symlink(name, tmp)
    os.rename(tmp, link)
    os.set_blocking(master, False)
    print(f"serial_relay: {link} -> {name}", file=sys.stderr)
    return master, slave


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--link", required=True)
    ap.add_argument("--log", required=True)
    ap.add_argument("--duration", type=float, default=20)
    ap.add_argument("--start-after", type=float, default=1.5)
    ap.add_argument("--spacing", type=float, default=0.006)
    ap.add_argument("--garbage-at", type=float, action="append", default=[])
    ap.add_argument("--unplug-at", type=float, default=-1)
    ap.add_argument("--unplug-for", type=float, default=0.5)
    ap.add_argument("--rearm", type=float, default=0.5)
    a = ap.parse_args()
    rnd = random.Random(37)
    master, slave = make_pty(a.link)
    log = open(a.log, "w")
    log.write("t,left,right\n")
    src = None
    buf = bytearray()
    base = [0, 0]
    last = None          # continued counts of the last logged record
    last_booted = True   # the previous record's booted flag (the first record is no reset)
    armed_at = a.start_after
    last_sent = 0.0
    unplugged = False
    garbage = sorted(a.garbage_at)
    t0 = time.monotonic()
    stats = {"records": 0, "bad": 0, "forwarded": 0, "resets": 0, "source_opens": 0}
    while True:
        t = time.monotonic() - t0
        if t >= a.duration:
            break
        if src is None:
            try:
                src = os.open(a.source, os.O_RDONLY | os.O_NOCTTY | os.O_NONBLOCK)
                tty.setraw(src, termios.TCSANOW)
                stats["source_opens"] += 1
                buf.clear()
            except OSError:
                time.sleep(0.02)
                continue
        if garbage and t >= garbage[0]:
            garbage.pop(0)
            noise = bytes(0x80 + rnd.randrange(0x7F) for _ in range(48))
            os.write(master, noise[:20] + b"\x00" + noise[21:] + b"\x00")
        if a.unplug_at >= 0 and not unplugged and t >= a.unplug_at:
            unplugged = True
            os.close(master)
            os.close(slave)
            os.unlink(a.link)
            time.sleep(a.unplug_for)
            master, slave = make_pty(a.link)
            armed_at = time.monotonic() - t0 + a.rearm
        r, _, _ = select.select([src], [], [], 0.002)
        if not r:
            continue
        try:
            data = os.read(src, 256)
        except OSError:
            data = b""
        if not data:  # QEMU gone (the test restarts it: a controller reset)
            os.close(src)
            src = None
            continue
        buf += data
        while b"\x00" in buf:
            frame, _, rest = bytes(buf).partition(b"\x00")
            buf = bytearray(rest)
            if not frame:
                continue
            rec = decode(frame)
            if rec is None:
                stats["bad"] += 1
                continue
            stats["records"] += 1
            flags, seq, time_us, left, right = rec
            booted = bool(flags & 4)
            if booted and not last_booted and last is not None:
                base = list(last)  # the counters restarted from 0: continue from the last
                stats["resets"] += 1
            last_booted = booted
            now = time.monotonic() - t0
            if now < armed_at:
                # Not forwarded, so odometryd never sees it: but a reset in it still counts.
                if last is not None:
                    last = [base[0] + left, base[1] + right]
                continue
            wait = last_sent + a.spacing - time.monotonic()
            if wait > 0:
                time.sleep(wait)
            try:
                os.write(master, frame + b"\x00")
            except OSError:
                continue
            last_sent = time.monotonic()
            last = [base[0] + left, base[1] + right]
            log.write(f"{last_sent - t0:.6f},{last[0]},{last[1]}\n")
            stats["forwarded"] += 1
    log.close()
    print("serial_relay:", stats, file=sys.stderr)


if __name__ == "__main__":
    main()
