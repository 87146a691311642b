#!/usr/bin/env bash
# check_core.sh - the house rules that a compiler or configure step does not check by itself
# (README "Layout", issue 33). Exit 1 with the offending lines when a rule is broken.
#   portable   the core rooms (hal, odometry, calibration, loop, protocol) include no Linux or
#              POSIX header, start no thread, use no C++ stream (iostream, sstream: their locale
#              machinery is 88 KB of a microcontroller's flash; hal/format.hpp words numbers),
#              and compile with -fno-exceptions -fno-rtti (preset core-portable: those
#              libraries only); the microcontroller build stands on this
#   composition  firmware/ (the composition root) does no raw Linux I/O: no header of files,
#              sockets, ioctl or file systems (fcntl.h, unistd.h, sys/*, linux/*, termios.h,
#              poll.h); that is drivers/' job (issue 33). Threads and their semaphores stay.
#   functions  no function of the project's own code (tests excepted) is longer than 60 lines
#              (tools/function_size.py: universal-ctags' function extents, counted as clang-tidy's
#              readability-function-size LineThreshold counts them)
#   tests      every GoogleTest target is named after its tier and unit (`<label>_<unit>`,
#              tests/CMakeLists.txt's odo_add_gtest), so a test's tier is in its name (issue 33)
# The layer table needs no check here: configure (odo_check_layers) fails on a wrong link.
# Usage: tools/check_core.sh [portable] [composition] [functions] [tests]   (default: all four)
set -euo pipefail
ODO_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ODO_ROOT"
core_rooms=(hal odometry calibration loop protocol)
max_lines=60
rc=0

check_portable() {
  local bad
  # Headers of an operating system, of threads and of stream I/O: none in the core.
  bad=$(grep -rnE '#include <(unistd\.h|fcntl\.h|poll\.h|termios\.h|pthread\.h|sys/[a-z_/]+\.h|linux/[a-z_/]+\.h|iostream|fstream|sstream|ostream|istream|iomanip|locale|thread|mutex|condition_variable|future|filesystem)>' \
    "${core_rooms[@]}" || true)
  bad+=$(grep -rnE 'std::(thread|jthread|async)\b|pthread_create|std::(o|i)?stringstream|std::(cout|cerr|clog)\b' \
    "${core_rooms[@]}" || true)
  if [[ -n $bad ]]; then
    echo "check_core: portable: the core rooms must not use these (Linux, POSIX, threads, streams):"
    echo "$bad"
    rc=1
  fi
  cmake --preset core-portable >/dev/null
  if ! cmake --build --preset core-portable -j"${ODO_JOBS:-$(nproc)}"; then
    echo "check_core: portable: the core rooms do not build with -fno-exceptions -fno-rtti"
    rc=1
  else
    echo "check_core: portable: ${core_rooms[*]}: no OS header, thread or stream; built with -fno-exceptions -fno-rtti"
  fi
}

check_composition() {
  local bad
  bad=$(grep -rnE '#include <(unistd\.h|fcntl\.h|poll\.h|termios\.h|sys/[a-z_/]+\.h|linux/[a-z_/]+\.h)>' \
    firmware || true)
  if [[ -n $bad ]]; then
    echo "check_core: composition: firmware/ must leave Linux I/O to drivers/:"
    echo "$bad"
    rc=1
  else
    echo "check_core: composition: firmware/ includes no Linux I/O header"
  fi
}

check_functions() {
  local files out
  # The project's own sources, tests and generated code excepted.
  mapfile -t files < <(git ls-files '*.cpp' | grep -vE '^(tests|build)/')
  # universal-ctags, not clang-tidy: clang-tidy parsed every file (190 s of CPU, a sixth of the
  # rules stage, at stop 42) to count lines that ctags finds in a second; on every function
  # flagged at a threshold of 40 lines the two agreed, file, line and name (stop 43).
  local frc=0
  out=$(tools/function_size.py "$max_lines" "${files[@]}") || frc=$?
  if ((frc == 1)); then
    echo "check_core: functions: longer than $max_lines lines (split them):"
    echo "$out"
    rc=1
  elif ((frc != 0)); then
    echo "check_core: functions: the check could not run: $out"
    rc=1
  else
    echo "check_core: functions: ${#files[@]} files, no function over $max_lines lines"
  fi
}

check_tests() {
  local bad
  # odo_add_gtest(NAME LABEL TIER ...): NAME must start with TIER_.
  bad=$(grep -oE 'odo_add_gtest\([A-Za-z0-9_]+ LABEL [a-z0-9]+' tests/CMakeLists.txt |
    sed -E 's/odo_add_gtest\(([A-Za-z0-9_]+) LABEL ([a-z0-9]+)/\1 \2/' |
    awk '{ if (index($1, $2 "_") != 1) print "  " $1 " (label " $2 ")" }')
  if [[ -n $bad ]]; then
    echo "check_core: tests: a test target's name must start with its tier (<label>_<unit>):"
    echo "$bad"
    rc=1
  else
    echo "check_core: tests: every test target is named <tier>_<unit>"
  fi
}

checks=("$@")
((${#checks[@]})) || checks=(portable composition functions tests)
for c in "${checks[@]}"; do
  case $c in
    portable) check_portable ;;
    composition) check_composition ;;
    functions) check_functions ;;
    tests) check_tests ;;
    *) echo "check_core: unknown check $c" >&2; exit 2 ;;
  esac
done
exit $rc
