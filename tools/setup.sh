#!/usr/bin/env bash
# setup.sh - install the Debian 12 packages this project needs (only the missing ones).
#   tools/setup.sh            build + demo dependencies
#   tools/setup.sh --tests    plus everything the test suite uses
# Runs apt-get only when something is missing. `apt-get update` may fail on one mirror list once
# a foreign architecture is configured; that is tolerated and a missing package still fails loudly.
set -euo pipefail

build_pkgs=(g++ cmake make pkg-config python3 libeigen3-dev libgpiod-dev libtomlplusplus-dev
  libcli11-dev nlohmann-json3-dev)
test_pkgs=(libgtest-dev libgmock-dev libbenchmark-dev valgrind
  clang-14 libclang-rt-14-dev libfuzzer-14-dev)  # fuzz preset: clang-14 + libFuzzer (TESTING.md)

want=("${build_pkgs[@]}")
for arg in "$@"; do
  case $arg in
    --tests) want+=("${test_pkgs[@]}") ;;
    *) echo "setup.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup.sh: all ${#want[@]} packages present"
  exit 0
fi
SUDO=
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
echo "setup.sh: installing ${missing[*]}"
$SUDO apt-get update -qq || echo "setup.sh: apt-get update reported an error (continuing; see above)" >&2
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
