#!/usr/bin/env bash
# demo.sh - set up, build and run the firmware on the simulated robot (README, command 1).
#   tools/demo.sh                  the shipped config: the UMBmark LabMate drives one 4 m square
#   tools/demo.sh --duration 20    any odometryd option is passed through
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cmake --preset demo >/dev/null
cmake --build --preset demo -j"$(nproc)"
args=("$@")
if ((${#args[@]} == 0)); then args=(--duration 100); fi
exec build/demo/firmware/odometryd --config firmware/config/odometryd.toml "${args[@]}"
