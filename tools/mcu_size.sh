#!/usr/bin/env bash
# mcu_size.sh - the flash an image takes (text + data, as arm-none-eabi-size counts them: data is
# stored in flash and copied to RAM at start-up) against board/flash_limit.txt.
#   tools/mcu_size.sh [ELF [LIMIT_FILE]]
#   ELF         default build/mcu-stm32f405/board/odo_mcu.elf (the real board, no simulator)
#   LIMIT_FILE  default board/flash_limit.txt (its one line that is not a comment: bytes)
# Prints "mcu_size: ELF flash F B (text T + data D) of limit L B: M B left" and exits 0 when
# F < L; 1 when over (or at) the limit; 2 when the image, the limit or arm-none-eabi-size is
# missing.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
elf=${1:-$root/build/mcu-stm32f405/board/odo_mcu.elf}
limit_file=${2:-$root/board/flash_limit.txt}
size=${ODO_SIZE:-arm-none-eabi-size}
[[ -f $elf ]] || { echo "mcu_size: $elf missing (cmake --build --preset mcu-stm32f405)"; exit 2; }
command -v "$size" >/dev/null || { echo "mcu_size: $size missing"; exit 2; }
limit=$(grep -vE '^[[:space:]]*(#|$)' "$limit_file" | head -1 | tr -d '[:space:]')
[[ $limit =~ ^[0-9]+$ ]] || { echo "mcu_size: no limit in $limit_file"; exit 2; }
read -r text data _ < <("$size" -B "$elf" | sed -n 2p)
flash=$((text + data))
if ((flash < limit)); then
  echo "mcu_size: $elf flash $flash B (text $text + data $data) of limit $limit B: $((limit - flash)) B left"
  exit 0
fi
echo "mcu_size: $elf flash $flash B (text $text + data $data) NOT below the limit $limit B ($limit_file): $((flash - limit)) B over"
exit 1
