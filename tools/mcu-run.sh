#!/usr/bin/env bash
# mcu-run.sh - the microcontroller firmware (board/, issue 36) in QEMU's netduinoplus2 (STM32F405),
# its serial lines wherever a test or a person wants them.
#
#   tools/mcu-run.sh [--elf PATH] [--usart1 SPEC] [--usart2 SPEC] [--serial-hz HZ]
#                    [--duration S] [--rate-hz HZ] [--covariance-ticks N] [--virtual] [--fault]
#                    [-- extra qemu-system-arm args]
#
#   --elf PATH      the image (default build/mcu-stm32f405/board/odo_mcu_qemu.elf; odo_mcu_qemu_w2.elf:
#                   two wheels per side, serial counts version 2; build them with
#                   cmake --preset mcu-stm32f405 && cmake --build --preset mcu-stm32f405)
#   --usart1 SPEC   USART1: the CAN pose protocol as SLCAN plus '#' report lines (default stdio)
#   --usart2 SPEC   USART2: the serial counts stream (protocol/serial_counts.hpp; default null)
#                   SPEC is a QEMU character device as -serial takes it: stdio, null, pty (QEMU
#                   prints the /dev/pts/N it made), file:PATH, unix:PATH,server=on,wait=off,
#                   tcp::PORT,server=on,wait=off, or a host tty/pty slave path (/dev/pts/N, /dev/ttyUSB0)
#   --serial-hz HZ  serial counts records per second: the loop rate (100 Hz) divided by a whole
#                   number, 0 = off (default 100; 576 is the most 115200 baud carries)
#   --duration S    seconds of loop time, 0 = forever (default: the simulated square + 1 s; the
#                   firmware then sends its final frames and QEMU exits with its exit code)
#   --rate-hz HZ    the loop rate (default 100; 50 Hz pose, 10 Hz Status and --serial-hz must
#                   divide it)
#   --covariance-ticks N  loop ticks merged into one covariance step, 1..100 (default 1; README
#                   "Pose uncertainty": 10 at 1 kHz)
#   --virtual       virtual time as fast as the host allows (-icount shift=0,sleep=off); default:
#                   paced at real time (-icount shift=0: one instruction a nanosecond, idle time
#                   waits for the wall clock), as a peer on a real line needs
#   --fault         end in a bus fault after start-up (the fault report on USART1, exit code 3)
# Exit code: QEMU's, i.e. the firmware's (0 after --duration; 3 after a fault).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
elf=$root/build/mcu-stm32f405/board/odo_mcu_qemu.elf
u1=stdio u2=null icount=shift=0 args=arg=odo extra=()
while (($#)); do
  case $1 in
    --elf) elf=$2; shift 2 ;;
    --usart1) u1=$2; shift 2 ;;
    --usart2) u2=$2; shift 2 ;;
    --serial-hz) args+=",arg=--serial-hz,arg=$2"; shift 2 ;;
    --duration) args+=",arg=--duration,arg=$2"; shift 2 ;;
    --rate-hz) args+=",arg=--rate-hz,arg=$2"; shift 2 ;;
    --covariance-ticks) args+=",arg=--covariance-ticks,arg=$2"; shift 2 ;;
    --virtual) icount=shift=0,sleep=off; shift ;;
    --fault) args+=",arg=--fault"; shift ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "mcu-run.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
[[ -f $elf ]] || { echo "mcu-run.sh: $elf not built (cmake --build --preset mcu-stm32f405)" >&2; exit 2; }
# A host device path: QEMU opens it as a serial port (tty: ... for a pty slave works the same).
dev() { if [[ $1 == /dev/* ]]; then echo "tty:$1"; else echo "$1"; fi; }
exec qemu-system-arm -M netduinoplus2 -display none -monitor none \
  -serial "$(dev "$u1")" -serial "$(dev "$u2")" -kernel "$elf" -icount "$icount" \
  -semihosting-config "enable=on,target=native,$args" "${extra[@]}"
