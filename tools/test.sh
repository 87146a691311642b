#!/usr/bin/env bash
# test.sh - set up and run the whole test suite (README, command 2; CI runs exactly this).
# Builds and tests, in order:
#   default     RelWithDebInfo: unit, sim, cli tiers
#   debug-asan  Debug + AddressSanitizer + UndefinedBehaviorSanitizer: unit, sim, cli tiers
#   cross-aarch64, cross-armhf
#               Release -O2 cross builds (toolchains/) of only what those tiers run (target
#               odo_tier_tests); the unit, sim, cli tiers run under qemu-user
#               (CMAKE_CROSSCOMPILING_EMULATOR)
#   packages    the Debian package of default (amd64) and of each cross build, checked by
#               tests/package/check_deb.sh; the amd64 one is installed, run, verified with
#               systemd-analyze, removed and purged on this machine (CI is throw-away), and
#               installed with apt on a fresh debootstrap chroot (tests/package/fresh_install.sh)
#   kernel      the `kernel` tier of the default build, inside a QEMU VM with Debian's kernel
#               (tools/vm-run.sh: vcan, gpio-sim, mtdram); if the VM cannot start, those tests
#               run on the host, where each one reports itself skipped with the reason
# Environment: ODO_JOBS (parallel build jobs, default nproc), ODO_CONFIGS (space-separated
# subset of the configurations above), ODO_PACKAGES=0 (no package checks), ODO_FRESH_INSTALL=0
# (no chroot install).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${ODO_JOBS:-$(nproc)}
configs=${ODO_CONFIGS:-"default debug-asan cross-aarch64 cross-armhf"}
if [[ " $configs " == *" cross-"* ]]; then tools/setup.sh --tests --cross; else tools/setup.sh --tests; fi
status=0
summary=()
for c in $configs; do
  echo "=== configuration $c ==="
  t0=$(date +%s)
  cmake --preset "$c" >/dev/null
  cmake --build --preset "$c" -j"$jobs"
  if ctest --preset "$c" -j"$jobs" --label-regex 'unit|sim|cli'; then r=ok; else r=FAILED; status=1; fi
  summary+=("$c: $r ($(($(date +%s) - t0)) s)")
done
if [[ " $configs " == *" default "* && ${ODO_KERNEL:-1} == 1 ]]; then
  echo "=== kernel tier (VM harness) ==="
  t0=$(date +%s)
  if prep=$(tools/vm-run.sh --prepare 2>&1); then
    # One vCPU: with two, gpio-sim edges can be lost under TCG (see tools/vm-run.md).
    if ODO_IN_VM=1 tools/vm-run.sh --cpus 1 --mem 1G --timeout 1800 -- \
        ctest --test-dir build/default -L kernel --output-on-failure; then r=ok; else r=FAILED; status=1; fi
  else
    echo "kernel tier: the VM harness is unavailable; kernel tests will report SKIPPED:"
    echo "$prep" | tail -5
    if ctest --test-dir build/default -L kernel --output-on-failure; then r="skipped (no VM)"; else r=FAILED; status=1; fi
  fi
  summary+=("kernel: $r ($(($(date +%s) - t0)) s)")
fi
if [[ ${ODO_PACKAGES:-1} == 1 ]]; then
  for c in $configs; do
    [[ $c == default || $c == cross-* ]] || continue
    echo "=== package of $c ==="
    t0=$(date +%s)
    # ctest exits 0 for a skipped test; the summary then says why from the test output.
    if ODO_PACKAGE_INSTALL=1 ctest --test-dir "build/$c" -L package --output-on-failure -V \
        >"build/$c/package.log" 2>&1
    then r=ok; else r=FAILED; status=1; fi
    # Every check is in build/$c/package.log; show failures, skips, sizes and the count.
    log=build/$c/package.log
    grep -E '^[0-9]+: (FAIL|SKIPPED|size|package|check_deb)' "$log" | cut -d' ' -f2- || true
    grep -Eq '^[0-9]+: SKIPPED|check_deb .*SKIPPED' "$log" && r="$r (part skipped, see above)"
    summary+=("package $c: $r ($(($(date +%s) - t0)) s)")
    if [[ $c == default && ${ODO_FRESH_INSTALL:-1} == 1 ]]; then
      # The amd64 package on a freshly bootstrapped Debian 12 (chroot): Depends from the mirror.
      echo "=== fresh install (debootstrap chroot) ==="
      t0=$(date +%s)
      deb=$(ls -t build/default/diffodom_*_amd64.deb | head -1)
      rc=0; tests/package/fresh_install.sh "$deb" || rc=$?
      case $rc in 0) r=ok ;; 77) r="skipped (see above)" ;; *) r=FAILED; status=1 ;; esac
      summary+=("fresh install amd64: $r ($(($(date +%s) - t0)) s)")
    fi
  done
fi
echo "=== summary ==="
printf '%s\n' "${summary[@]}"
exit $status
