#!/usr/bin/env python3
"""mcu_profile.py - a flat profile of the microcontroller firmware's tick in QEMU (issue 36).

QEMU 7.2 as Debian ships it has no TCG plugins, but its -d log lists every translation block as it
is translated (in_asm: its guest instructions, under the symbol it starts in) and every block as
it is executed (exec, with nochain so that none is skipped). Instructions per symbol are the
executed blocks' instruction counts summed. Two runs that differ only in --duration give the
start-up's share twice, so their difference over the extra ticks is the cost of a tick (the
simulated robot's SysTick interrupt and the idle loop included):

  for d in 1 2; do
    qemu-system-arm -M netduinoplus2 -display none -monitor none -serial null -serial null \\
      -kernel build/mcu-stm32f405/board/odo_mcu_qemu.elf -icount shift=0,sleep=off \\
      -semihosting-config enable=on,target=native,arg=odo,arg=--duration,arg=$d \\
      -d in_asm,exec,nochain -D /tmp/mcu$d.log     # ~40 MB a second of loop time (100 ticks)
  done
  tools/mcu_profile.py /tmp/mcu1.log /tmp/mcu2.log 100

usage: mcu_profile.py SHORT_LOG LONG_LOG EXTRA_TICKS [ROWS]
"""
import collections
import re
import sys


def profile(path):
    """Instructions executed per symbol in one QEMU -d in_asm,exec,nochain log."""
    blocks = {}  # guest pc -> (instructions, symbol) of its latest translation
    per = collections.Counter()
    pc, sym, n = None, "?", 0

    def close():
        if pc is not None:
            blocks[pc] = (n, sym)

    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("IN:"):
                close()
                pc, sym, n = None, line[3:].strip() or "?", 0
            elif line.startswith("0x"):
                if pc is None:
                    pc = int(line[2:10], 16)
                n += 1
            elif line.startswith("Trace"):
                close()
                pc = None
                m = re.search(r"/([0-9a-f]{8})/", line)
                if m:
                    k, s = blocks.get(int(m.group(1), 16), (0, "?"))
                    per[s] += k
    return per


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    short, long_ = profile(sys.argv[1]), profile(sys.argv[2])
    ticks = float(sys.argv[3])
    rows = int(sys.argv[4]) if len(sys.argv) > 4 else 30
    diff = {s: long_[s] - short[s] for s in set(short) | set(long_)}
    print(f"{sum(diff.values()) / ticks:10.1f}  instructions a tick in all")
    for s, v in sorted(diff.items(), key=lambda x: -x[1])[:rows]:
        print(f"{v / ticks:10.1f}  {s}")


if __name__ == "__main__":
    main()
