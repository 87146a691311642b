#!/usr/bin/env bash
# setup.sh - install the Debian 12 packages this project needs (only the missing ones).
#   tools/setup.sh            build + demo dependencies
#   tools/setup.sh --tests    plus everything the test suite uses
#   tools/setup.sh --cross    plus the arm64/armhf cross builds (cross compilers, qemu-user, the
#                             :arm64/:armhf -dev packages; adds the two dpkg architectures)
# Runs apt-get only when something is missing. `apt-get update` may fail on one mirror list once
# a foreign architecture is configured; that is tolerated and a missing package still fails loudly.
set -euo pipefail

build_pkgs=(g++ cmake make pkg-config python3 libeigen3-dev libgpiod-dev libtomlplusplus-dev
  libcli11-dev nlohmann-json3-dev
  cyclonedds-dev cyclonedds-tools)  # ROS 2 output (ros2/, -DODO_ROS2=OFF without): idlc, libddsc
test_pkgs=(libgtest-dev libgmock-dev libbenchmark-dev valgrind
  can-utils python3-can iproute2  # CAN kernel tests in the VM (candump, cansend, ip, tc)
  rt-tests stress-ng systemd  # cyclictest + load for tools/jitter.sh; systemd-analyze verify
  clang-14 libclang-rt-14-dev libfuzzer-14-dev  # fuzz preset: clang-14 + libFuzzer (TESTING.md)
  universal-ctags  # tools/check_core.sh: no function over 60 lines (tools/function_size.py)
  tmux librsvg2-bin  # cli_umbmark_tty (a real terminal), cli_umbmark_svg (rsvg-convert)
  libfastrtps-dev fastddsgen  # the independent Fast DDS peer of the ROS 2 tests (fastddsgen: Java)
  # The microcontroller firmware (preset mcu-stm32f405, board/) and its QEMU tests (stage mcu).
  gcc-arm-none-eabi picolibc-arm-none-eabi libstdc++-arm-none-eabi-picolibc qemu-system-arm)
# cli_can reads the DBC with the npm library candied (tests/tools/dbc_candied.cjs): node and npm.
# Only when the machine has no node/npm commands: our machine image ships Node.js from
# NodeSource, whose nodejs package bundles npm and Conflicts: npm, so asking apt for Debian's
# npm there fails the whole install ("held broken packages").
node_pkgs=(nodejs npm)
# npm packages of the tests, installed into tools/node/ (not committed; cli_can looks there).
npm_test_pkgs=(candied@2.2.0)
# Cross builds (toolchains/, presets cross-aarch64 and cross-armhf) and the package checks
# (tests/package/: check_deb.sh uses dpkg-shlibdeps, file, systemd-analyze; fresh_install.sh
# uses debootstrap).
cross_pkgs=(g++-aarch64-linux-gnu g++-arm-linux-gnueabihf qemu-user dpkg-dev file systemd
  debootstrap)
cross_archs=(arm64 armhf)
# Target libraries linked into the binaries or tests (Multi-Arch: same; one per architecture).
# Eigen, CLI11 and nlohmann-json are Architecture: all headers: the native package serves all.
# No cyclonedds-dev here: the cross presets build with ODO_ROS2=OFF. cyclonedds-dev:<arch> needs
# libssl3:<arch> of exactly the native libssl3's version, and the native one comes from
# bookworm-security, whose armhf list is the one that fails to download on our machines
# (README, Cross builds): apt then refuses with "held broken packages", so CI would depend on a
# mirror's sync state.
cross_arch_pkgs=(libgpiod-dev libtomlplusplus-dev libgtest-dev libgmock-dev)

want=("${build_pkgs[@]}")
add_archs=()
npm_want=()
for arg in "$@"; do
  case $arg in
    --tests)
      want+=("${test_pkgs[@]}"); npm_want+=("${npm_test_pkgs[@]}")
      if ! command -v node >/dev/null || ! command -v npm >/dev/null; then want+=("${node_pkgs[@]}"); fi
      ;;
    --cross)
      want+=("${cross_pkgs[@]}")
      for a in "${cross_archs[@]}"; do
        for p in "${cross_arch_pkgs[@]}"; do want+=("$p:$a"); done
        dpkg --print-foreign-architectures | grep -qx "$a" || add_archs+=("$a")
      done
      ;;
    *) echo "setup.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

# npm_install: the npm test packages into tools/node (after the Debian packages: needs npm).
npm_install() {
  ((${#npm_want[@]} == 0)) && return 0
  local dir
  dir="$(cd "$(dirname "$0")" && pwd)/node"
  for p in "${npm_want[@]}"; do
    if [ -f "$dir/node_modules/${p%@*}/package.json" ] &&
      grep -q "\"version\": \"${p#*@}\"" "$dir/node_modules/${p%@*}/package.json"; then
      continue
    fi
    echo "setup.sh: npm install --prefix $dir $p"
    npm install --no-audit --no-fund --prefix "$dir" "$p"
  done
}

missing=()
for p in "${want[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup.sh: all ${#want[@]} packages present"
  npm_install
  exit 0
fi
SUDO=
if [ "$(id -u)" != 0 ]; then SUDO=sudo; fi
echo "setup.sh: installing ${missing[*]}"
for a in "${add_archs[@]}"; do
  echo "setup.sh: dpkg --add-architecture $a"
  $SUDO dpkg --add-architecture "$a"
done
$SUDO apt-get update -qq || echo "setup.sh: apt-get update reported an error (continuing; see above)" >&2
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
npm_install
