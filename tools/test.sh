#!/usr/bin/env bash
# test.sh - set up and run the whole test suite (README, command 2; CI runs exactly this).
# Builds and tests, in order:
#   default     RelWithDebInfo: unit, sim, cli tiers; beside them, at nice 19, the studies (label
#               study: UMBmark noise, self-calibration over 300 seeds)
#   soak        the `soak` tier of the default build: 24 h of simulated driving with random
#               faults in virtual time (ODO_SOAK=0 skips it)
#   mcu         (after default) the microcontroller firmware: preset mcu-stm32f405 built, the
#               real-board images' flash checked against board/flash_limit.txt (tools/mcu_size.sh:
#               over it, the stage fails), then
#               tests/mcu/test_mcu_qemu.sh in qemu-system-arm (ODO_MCU=0 skips it; under CI a
#               missing toolchain or QEMU fails it); the kernel tier's kernel_mcu_slcan uses its
#               image
#   kernel      the `kernel` tier of the default build, inside a QEMU VM with Debian's kernel
#               (tools/vm-run.sh: vcan, gpio-sim, mtdram, at24); if the VM cannot start, the stage
#               fails under CI; elsewhere those tests run on the host, where each one reports
#               itself skipped with the reason
#   debug-asan  Debug + AddressSanitizer + UndefinedBehaviorSanitizer: unit, sim, cli tiers (but the
#               pure-math studies: pure_math_studies below), then
#               the kernel tier in the VM (the drivers on real kernel facilities) but for the
#               repeated-SIGKILL tests; any sanitizer report, of a test or of a program it started,
#               fails the stage
#   tsan        ThreadSanitizer: unit, sim, cli tiers but the pure-math studies (every threaded
#               test: TESTING.md), then the
#               GPIO quadrature decoder's kernel tests in the VM (its event thread on gpio-sim)
#   fuzz        clang-14 libFuzzer + ASan + UBSan: a short run of every fuzz target (ODO_FUZZ_ARGS,
#               default -max_total_time=10 per target)
#   cross-aarch64, cross-armhf
#               Release -O2 cross builds (toolchains/) of only what those tiers run (target
#               odo_tier_tests); the unit, sim, cli tiers run under qemu-user
#               (CMAKE_CROSSCOMPILING_EMULATOR), without the statistical studies of pure math
#               (soft float under the emulator: they run natively in default only); the cli tier
#               on armhf only (the 32-bit ABI; aarch64 is LP64 like amd64)
# While the VMs (or soak, or mcu's QEMU) leave CPU idle, the sanitizer trees are built beside
# them in the background at nice 19 (prebuild); the kernel tier's two long drives run in a
# second VM beside the first.
#   packages    the Debian package of default (amd64) and of each cross build, checked by
#               tests/package/check_deb.sh; the amd64 one is installed, run, verified with
#               systemd-analyze, removed and purged on this machine (CI is throw-away), and
#               installed with apt on a fresh debootstrap chroot (tests/package/fresh_install.sh)
#   rules       after default: tools/check_core.sh (the core rooms portable: no OS header, thread
#               or stream, built with -fno-exceptions -fno-rtti; firmware/ no Linux I/O header;
#               no function over 60 lines)
# Environment: ODO_JOBS (parallel build jobs, default nproc), ODO_CONFIGS (space-separated
# subset of the configurations above), ODO_RULES=0, ODO_SOAK=0, ODO_KERNEL=0, ODO_MCU=0, ODO_PACKAGES=0 (skip those
# stages), ODO_FRESH_INSTALL=0 (no chroot install).
#
# A skip is for a developer's machine that lacks something, never for CI: with CI=true (as CI
# runs it) a stage in which any test reports skipped, a stage that cannot run at all (the VM
# harness, the chroot), or a stage that ran no test fails the run, and the summary names why.
# The stage functions can be sourced for tests (tests/ci/test_ci_gate.sh): main runs only when
# this file is executed.
set -euo pipefail
ODO_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
status=0
summary=()
n_pass=0 n_fail=0 n_skip=0  # over every ctest run, for the closing line
# "log: test (reason)" and a few lines of why, printed with the summary: CI keeps only the tail
# of this script's output, so a failed test must be named at the end too, not only where ctest
# printed it an hour earlier.
failures=()

in_ci() { [[ ${CI:-} == true || ${CI:-} == 1 ]]; }

# ci_gate STAGE SKIPPED RAN: under CI, a stage with skipped tests or with none run is a failure.
# Prints the reason and returns 1 then; returns 0 otherwise (and always outside CI).
ci_gate() {
  local stage=$1 skipped=$2 ran=$3
  in_ci || return 0
  if ((skipped > 0)); then
    echo "$stage: FAILED under CI: $skipped test(s) reported skipped (a skip is never a pass in CI)"
    return 1
  fi
  if ((ran == 0)); then
    echo "$stage: FAILED under CI: no test ran"
    return 1
  fi
  return 0
}

# counted LOG CMD...: runs CMD (a ctest run, possibly inside the VM), output to the terminal and
# LOG, and adds its "N% tests passed, F tests failed out of T" figures to the totals.
counted() {
  local log=$1 rc line total failed skipped; shift
  last_ran=0 last_skipped=0
  set +e
  "$@" 2>&1 | tee "$log"
  rc=${PIPESTATUS[0]}
  set -e
  line=$(grep -E '[0-9]+% tests passed, [0-9]+ tests failed out of [0-9]+' "$log" | tail -1 || true)
  if [[ -n $line ]]; then
    total=$(sed -E 's/.* out of ([0-9]+).*/\1/' <<<"$line")
    failed=$(sed -E 's/.*passed, ([0-9]+) tests failed.*/\1/' <<<"$line")
    skipped=$(grep -cE '\*\*\*Skipped' "$log" || true)
    n_pass=$((n_pass + total - failed - skipped)) n_fail=$((n_fail + failed))
    n_skip=$((n_skip + skipped))
    last_ran=$total last_skipped=$skipped
    if [[ $skipped != 0 ]]; then  # name them: the reason is in each test's output above
      echo "skipped in $log:"; grep -E '\*\*\*Skipped' "$log" || true
    fi
    if [[ $failed != 0 ]]; then note_failures "$log"; fi
  elif [[ $rc != 0 ]]; then
    n_fail=$((n_fail + 1))  # the run itself failed before any test reported
  fi
  return "$rc"
}

# note_failures LOG: adds each test ctest listed as failed in LOG to `failures`, with the first
# lines of GoogleTest's "Failure" reports and of the script tests' "FAIL: <check>" lines in LOG
# (at most 12, so the summary stays readable: CI shows only the tail of the run).
note_failures() {
  local log=$1 t
  while IFS= read -r t; do failures+=("$log: ${t#"${t%%[![:space:]]*}"}"); done < <(
    sed -n '/The following tests FAILED:/,$p' "$log" | grep -E '^[[:space:]]+[0-9]+ - ' || true)
  while IFS= read -r t; do failures+=("    $t"); done < <(
    grep -A3 -E ': Failure$|\*\*\*(Timeout|Exception)|^FAIL: ' "$log" | grep -v -e '^--$' -e '^[[:space:]]*$' | head -12 || true)
}

# gated STAGE LOG CMD...: `counted`, then the CI gate over what that run reported. Returns 0
# only when the run passed and (under CI) nothing was skipped and something ran.
gated() {
  local stage=$1 log=$2; shift 2
  local rc=0
  counted "$log" "$@" || rc=$?
  if ! ci_gate "$stage" "$last_skipped" "$last_ran"; then
    # Under CI a skipped test is a failed one, in the closing line too (its skipped count is 0).
    if ((last_skipped > 0)); then
      n_skip=$((n_skip - last_skipped)) n_fail=$((n_fail + last_skipped))
    elif ((rc == 0)); then n_fail=$((n_fail + 1)); fi  # nothing ran: one failure for the stage
    return 1
  fi
  return "$rc"
}

# build_config CONFIG JOBS: configures and builds one configuration's preset.
build_config() {
  # Under CI the project's own warnings are errors (ODO_WERROR); set either way, so that a
  # build tree keeps no earlier run's choice.
  local werror=OFF
  if in_ci; then werror=ON; fi
  # Under CI the default tree keeps line tables only (-g1, as the sanitizer presets): debug
  # information does not change the code GCC generates, the package strips it anyway, and full
  # -g is a quarter of every file's compile. A developer's default tree keeps full -g.
  local flags=() g=-g  # -g: CMake's own default for GCC
  if in_ci; then g=-g1; fi
  if [[ $1 == default ]]; then flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 $g -DNDEBUG"); fi
  cmake --preset "$1" -DODO_WERROR=$werror "${flags[@]}" >/dev/null &&
    cmake --build --preset "$1" -j"$2"
}

# prebuild CONFIG...: builds the CONFIGs one after another in the background, at nice 19 on
# every core, while stages that leave CPU idle run (the kernel tier's VM is one emulated CPU and
# used 47 % of it over the tier at stop 40; soak is one test; mcu's QEMU one thread). When a
# CONFIG's own stage comes, prebuild_stop leaves a tree already built alone, or stops the build
# of the tree it is on (that stage builds the rest in the foreground) and keeps the trees after
# it for prebuild_resume. Output: build/CONFIG-prebuild.log; a failed prebuild is not judged
# here: stage_config builds again and reports that build.
declare -A prebuilt=()  # CONFIG -> pid of the background builder that has it in its queue
prebuild_queue=() prebuild_rest=()
prebuild() {
  local queue=() c
  for c in "$@"; do
    if [[ " $configs " == *" $c "* && -z ${prebuilt[$c]:-} ]]; then queue+=("$c"); fi
  done
  ((${#queue[@]} > 0)) || return 0
  mkdir -p build
  # Written before the builder starts, so that a stage coming at once finds its tree there and
  # stops the builder (prebuild_stop) instead of building beside it.
  echo "${queue[0]}" >build/prebuild.current
  # nice 19: a stage beside it keeps its CPU (the kernel tier's timing tests, e.g. the CAN
  # link-down gap, failed in a fresh-chroot run whose VM shared the machine with builds at nice
  # 0); the builds take only what that stage leaves idle.
  # setsid: its own process group, so that prebuild_stop reaches make and the compilers.
  setsid nice -n 19 bash -c "$(declare -f in_ci build_config)
    for c in ${queue[*]}; do
      echo \$c >build/prebuild.current
      build_config \$c $jobs >build/\$c-prebuild.log 2>&1
    done
    rm -f build/prebuild.current" >/dev/null 2>&1 &
  for c in "${queue[@]}"; do prebuilt[$c]=$!; done
  prebuild_queue=("${queue[@]}")
  echo "=== building in the background: ${queue[*]} (build/CONFIG-prebuild.log) ==="
}

# The statistical studies of pure math (error-model Monte Carlo and fit, self-calibration over
# simulated drives): gtest suites, run natively in the default tree only (stage_config). Since
# stop 45 with issue 38's two: the skid step's Monte Carlo (ErrorModelIcr) and the
# self-calibration of the 4WD base over simulated excursions (SelfCalSkid4, 103 s under
# qemu-aarch64: the cross stage's longest test by 3x; `odomctl selfcal simulate --robot skid4`
# in cli_selfcal drives the same fit in every tree).
pure_math_studies='ErrorMonteCarlo|ErrorModelFit|ErrorModelIcr|SelfCalSim|SelfCalOpen|SelfCalSkid4'

# study_start: the default tree's label `study` (the 300-seed self-calibration studies, the
# UMBmark noise study: pure CPU, ~450 test-seconds) in the background at nice 19, beside the
# other tiers: those wait on daemons and timers for much of their time, and the studies take
# that idle CPU without taking a core from a timing test. study_wait judges them.
study_pid=''
study_start() {
  echo "=== default: the study tier in the background (build/default/ctest-study.log) ==="
  (
    renice -n 19 -p "$BASHPID" >/dev/null
    n_pass=0 n_fail=0 n_skip=0 failures=() r=0
    gated study build/default/ctest-study.log ctest --test-dir build/default -j"$jobs" -L study \
      >/dev/null 2>&1 || r=$?
    echo "$n_pass $n_fail $n_skip" >build/default/study.counts
    printf '%s\n' "${failures[@]}" >build/default/study.failures
    exit "$r"
  ) &
  study_pid=$!
}
study_wait() {
  local r=0 p f k line
  wait "$study_pid" || r=1
  read -r p f k <build/default/study.counts || true
  n_pass=$((n_pass + ${p:-0})) n_fail=$((n_fail + ${f:-1})) n_skip=$((n_skip + ${k:-0}))
  while IFS= read -r line; do [[ -n $line ]] && failures+=("$line"); done <build/default/study.failures
  echo "study (background): $([[ $r == 0 ]] && echo ok || echo FAILED), ${p:-0} passed, see build/default/ctest-study.log"
  return $r
}

# prebuild_stop CONFIG: CONFIG's stage has come. A background builder still on CONFIG is stopped
# (waiting for it on nice 19 left a core idle: at stop 37 the ASan tree's build ran 610 s more
# on one core after the kernel tier); make, stopped by SIGTERM, deletes the object file it was
# writing, and the foreground build picks up from the rest. The trees queued after CONFIG are
# kept in prebuild_rest for prebuild_resume. A builder past CONFIG goes on.
prebuild_stop() {
  local pid=${prebuilt[$1]:-} c after=0
  [[ -n $pid ]] || return 0
  unset "prebuilt[$1]"
  if ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null || true
    return 0
  fi
  [[ $(cat build/prebuild.current 2>/dev/null) == "$1" ]] || return 0
  kill -TERM -- "-$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  echo "$1: background build stopped; the rest builds on $jobs cores"
  for c in "${prebuild_queue[@]}"; do
    if ((after)); then prebuild_rest+=("$c"); unset "prebuilt[$c]"; fi
    if [[ $c == "$1" ]]; then after=1; fi
  done
}

# prebuild_resume: the trees prebuild_stop took from a stopped builder, in the background again.
prebuild_resume() {
  ((${#prebuild_rest[@]} > 0)) || return 0
  local rest=("${prebuild_rest[@]}")
  prebuild_rest=()
  prebuild "${rest[@]}"
}

stage_config() {  # build one configuration and run its ctest tiers
  local c=$1 t0 r labels exclude=()
  echo "=== configuration $c ==="
  t0=$(date +%s)
  prebuild_stop "$c"
  if build_config "$c" "$jobs"; then
    labels='unit|sim|cli'
    # The self-test of this script's CI gate (label ci) only in the native default build.
    if [[ $c == default ]]; then labels='unit|sim|cli|ci'; fi
    if [[ $c == fuzz ]]; then labels=fuzz; fi
    # The cli tier (the real executables driven by scripts) under qemu-user on armhf only: it is
    # the ABI unlike amd64's (32-bit time_t, long and pointers; other alignment), where a file
    # format or a printed number can differ; aarch64 is LP64 like the native trees that run the
    # cli tier thrice. There the unit and sim tiers check the arm64 code generation: the tier
    # took 125 of cross-aarch64's 438 s (stop 38).
    if [[ $c == cross-aarch64 ]]; then labels='unit|sim'; fi
    # The statistical studies of pure math (pure_math_studies) run natively in default only:
    # - under qemu-user every double operation is the emulator's soft float: 100-300 times their
    #   native seconds, 72 % of cross-aarch64's test time at stop 37;
    # - they are single-threaded: ThreadSanitizer has nothing to race in them;
    # - under ASan + UBSan they took 565 of debug-asan's 1060 test-seconds (stop 38) for the
    #   functions their hand-derived unit tests (ErrorModel.*, SelfCal.*) and the CLI's
    #   simulate-and-fit runs (cli_selfcal, cli_errormodel) drive in every configuration.
    # The self-calibration soak (loop, recorder, store over hours) stays in the sanitizer tiers.
    case $c in
      cross-*) exclude=(--exclude-regex "^($pure_math_studies|SelfCalSoak)\\.") ;;
      tsan | debug-asan) exclude=(--exclude-regex "^($pure_math_studies)\\.") ;;
    esac
    if [[ $c == default ]]; then study_start; fi
    r=ok
    gated "$c" "build/$c/ctest-tiers.log" ctest --preset "$c" -j"$jobs" --label-regex "$labels" \
      "${exclude[@]}" || r=FAILED
    if [[ $c == default ]] && ! study_wait; then r=FAILED; fi
    if [[ $r != ok ]]; then status=1; fi
  else
    r="FAILED (build)"; status=1; n_fail=$((n_fail + 1))
  fi
  summary+=("$c: $r ($(($(date +%s) - t0)) s)")
}

stage_soak() {
  local t0 r
  echo "=== soak tier ==="
  t0=$(date +%s)
  if gated soak build/default/soak.log ctest --test-dir build/default -L soak -V >/dev/null
  then r=ok; else r=FAILED; status=1; tail -40 build/default/soak.log; fi
  grep -o 'soak: seed.*' build/default/soak.log || true
  summary+=("soak: $r ($(($(date +%s) - t0)) s)")
}

# The VM harness; a test may point this at another script (tests/ci/test_ci_gate.sh).
VM_RUN=${ODO_VM_RUN:-$ODO_ROOT/tools/vm-run.sh}

# The kernel tier's two long drives (a hundred SIGKILLs during motion, a two-minute stalled
# wheel), which stage_kernel runs each in a VM of its own.
kernel_long=(HundredSigkills OneWheelStalling)

# kernel_has TREE REGEX: true when TREE's kernel tier has a test matching REGEX (a test's tree
# may not have the long drives).
kernel_has() {
  ctest --test-dir "build/$1" -N -L kernel -R "$2" 2>/dev/null | grep -qE '^Total Tests: [1-9]'
}

# in_kernel_vm TREE REPORTS CTEST_ARGS...: ctest of build/TREE in the VM. One vCPU: with two,
# gpio-sim edges can be lost under TCG (see tools/vm-run.md). 2G: the sanitizers' shadow memory.
in_kernel_vm() {
  local tree=$1 reports=$2; shift 2
  ODO_IN_VM=1 ASAN_OPTIONS=log_path=$reports/asan \
    UBSAN_OPTIONS="log_path=$reports/ubsan print_stacktrace=1" \
    TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 log_path=$reports/tsan" \
    "$VM_RUN" --cpus 1 --mem 2G --rw "$reports" --timeout 1800 -- \
    ctest --test-dir "build/$tree" --output-on-failure "$@"
}

# replay_output FILE RC: prints FILE and exits RC (a finished run's output, for counted).
replay_output() { cat "$1"; return "$2"; }

# vm_prepare_start: the VM harness's kernel, modules and initramfs (tools/vm-run.sh --prepare) in
# the background from the start of the run, at nice 19. On a fresh machine that is the kernel
# packages' download and the gpio-sim build from Debian's kernel source (51 s of CPU; 186 s of
# wall time at stop 45 on a loaded machine with an empty cache), which the kernel stage used to
# wait for on the critical path. vm_prepare_wait: its output and exit status (without a
# background run, the stage's own call).
vm_prepare_pid=''
vm_prepare_start() {
  mkdir -p build
  (renice -n 19 -p "$BASHPID" >/dev/null; exec "$VM_RUN" --prepare) >build/vm-prepare.log 2>&1 &
  vm_prepare_pid=$!
}
vm_prepare_wait() {
  if [[ -z $vm_prepare_pid ]]; then "$VM_RUN" --prepare 2>&1; return; fi
  local r=0
  wait "$vm_prepare_pid" || r=$?
  vm_prepare_pid=''
  cat build/vm-prepare.log
  # A failed background run is repeated once in the foreground, so that a failure the later
  # call does not share (a mirror's hiccup) does not fail the stage.
  if ((r != 0)); then "$VM_RUN" --prepare 2>&1; fi
}

# stage_kernel [TREE [NAME [CTEST_ARGS...]]]: the kernel tier of build/TREE (default: default) in
# the VM, named NAME (default: kernel) in the summary. In a sanitizer tree the sanitizers write
# their reports to files in build/TREE/sanitizer-reports (a program a test starts and kills
# reports there too, where its stderr would be lost); any report fails the stage.
stage_kernel() {
  local tree=${1:-default} name=${2:-kernel} t0 r prep reports
  shift $(($# < 2 ? $# : 2))
  echo "=== $name tier (VM harness) ==="
  t0=$(date +%s)
  reports=$PWD/build/$tree/sanitizer-reports
  rm -rf "$reports" && mkdir -p "$reports"
  if prep=$(vm_prepare_wait); then
    local split=() long_pids=() long_logs=() re i
    if (($# == 0)); then
      # Each long drive (kernel_long) in a VM of its own beside the rest: they were 306 of the
      # tier's 441 test-seconds (stop 42) and mostly wait on the daemon's timers, so one VM's
      # one CPU left the machine idle; in one second VM together (stops 43-44) the tier took
      # their sum, 295 s; in two, the longer (stop 45's fresh-chroot run: 187 s, beside the
      # main VM's 133 s).
      for re in "${kernel_long[@]}"; do
        kernel_has "$tree" "$re" || continue
        long_logs+=("build/$tree/kernel-$re.log")
        in_kernel_vm "$tree" "$reports" -L kernel -R "$re" >"${long_logs[-1]}.out" 2>&1 &
        long_pids+=($!)
      done
      if ((${#long_pids[@]} > 0)); then
        split=(--exclude-regex "$(IFS='|'; echo "${kernel_long[*]}")")
      fi
    fi
    if gated "$name" "build/$tree/kernel.log" in_kernel_vm "$tree" "$reports" -L kernel "$@" "${split[@]}"
    then r=ok; else r=FAILED; status=1; fi
    for i in "${!long_pids[@]}"; do
      local long_rc=0
      wait "${long_pids[$i]}" || long_rc=$?
      # counted re-reads that VM's output, so that its tests enter the totals and the gate.
      if ! gated "$name" "${long_logs[$i]}" replay_output "${long_logs[$i]}.out" "$long_rc"; then
        r=FAILED; status=1
      fi
    done
    if compgen -G "$reports/*" >/dev/null; then
      echo "$name: sanitizer reports:"; head -n 30 "$reports"/*
      failures+=("$name: sanitizer reports in $reports")
      r=FAILED; status=1; n_fail=$((n_fail + 1))
    fi
  elif in_ci; then
    # Under CI the kernel tier is not optional: a machine that cannot boot the VM fails the run.
    echo "kernel tier: FAILED under CI: the VM harness cannot start:"
    echo "$prep" | tail -5
    r="FAILED (VM harness unavailable: $(grep -E '^vm-run:' <<<"$prep" | tail -1 || true))"
    status=1; n_fail=$((n_fail + 1))
  else
    echo "kernel tier: the VM harness is unavailable; kernel tests will report SKIPPED:"
    echo "$prep" | tail -5
    if counted "build/$tree/kernel.log" ctest --test-dir "build/$tree" -L kernel --output-on-failure "$@"
    then r="skipped (no VM)"; else r=FAILED; status=1; fi
  fi
  summary+=("$name: $r ($(($(date +%s) - t0)) s)")
}

stage_fresh_install() {  # the amd64 package on a freshly bootstrapped Debian 12 chroot
  local deb=$1 t0 r rc
  echo "=== fresh install (debootstrap chroot) ==="
  t0=$(date +%s)
  rc=0; tests/package/fresh_install.sh "$deb" || rc=$?
  case $rc in
    0) r=ok; n_pass=$((n_pass + 1)) ;;
    77) if in_ci; then r="FAILED under CI (skipped, see above)"; status=1; n_fail=$((n_fail + 1))
        else r="skipped (see above)"; n_skip=$((n_skip + 1)); fi ;;
    *) r=FAILED; status=1; n_fail=$((n_fail + 1)) ;;
  esac
  summary+=("fresh install amd64: $r ($(($(date +%s) - t0)) s)")
}

stage_mcu() {  # the microcontroller firmware (issue 36): its preset's build, the QEMU tests
  local t0 r=ok log=build/mcu.log line p f
  echo "=== mcu ==="
  t0=$(date +%s)
  if ! command -v qemu-system-arm >/dev/null || ! command -v arm-none-eabi-g++ >/dev/null; then
    # setup.sh --tests installs both: a machine without them cannot run the stage.
    if in_ci; then r="FAILED under CI (qemu-system-arm or arm-none-eabi-g++ missing)"; status=1
      n_fail=$((n_fail + 1))
    else r="skipped (qemu-system-arm or arm-none-eabi-g++ missing)"; n_skip=$((n_skip + 1)); fi
    summary+=("mcu: $r ($(($(date +%s) - t0)) s)")
    return 0
  fi
  set +e
  {
    cmake --preset mcu-stm32f405 -DODO_WERROR="$(in_ci && echo ON || echo OFF)" &&
      cmake --build --preset mcu-stm32f405 -j "$jobs" &&
      ODOMETRYD=build/default/firmware/odometryd ODOMCTL=build/default/odomctl/odomctl \
        tests/mcu/test_mcu_qemu.sh "$ODO_ROOT" build/mcu-stm32f405/board/odo_mcu_qemu.elf
  } >"$log" 2>&1
  local rc=$?
  set -e
  grep -E '^(FAIL|test_mcu_qemu)|odo_mcu(_qemu(_w2)?)?\.elf$' "$log" || true
  line=$(grep -E '^test_mcu_qemu: [0-9]+ passed, [0-9]+ failed' "$log" | tail -1 || true)
  if [[ -n $line ]]; then
    p=$(sed -E 's/.*: ([0-9]+) passed.*/\1/' <<<"$line") f=$(sed -E 's/.* ([0-9]+) failed.*/\1/' <<<"$line")
    n_pass=$((n_pass + p)) n_fail=$((n_fail + f))
  fi
  if [[ $rc != 0 ]]; then
    r="FAILED (see $log)"; status=1
    [[ -n $line ]] || n_fail=$((n_fail + 1))  # the build failed before any check ran
  fi
  # The real-board images' flash (one and two wheels per side) against board/flash_limit.txt
  # (BENCHMARKS.md's < 128 KB): over it, the stage fails, whatever the QEMU tests said.
  # (An image the build did not make: the build's failure above says so.)
  for p in odo_mcu odo_mcu_w2; do
    [[ -f build/mcu-stm32f405/board/$p.elf ]] || continue
    if tools/mcu_size.sh "build/mcu-stm32f405/board/$p.elf"; then n_pass=$((n_pass + 1))
    else r="FAILED ($p.elf's flash not below board/flash_limit.txt)"; status=1
      n_fail=$((n_fail + 1)) failures+=("mcu: $p.elf's flash not below board/flash_limit.txt"); fi
  done
  # The default tree's tests that need the image (label mcu: odometryd's serial backend against
  # the firmware in QEMU); gated, so a skip (no image) fails under CI.
  if ! gated "mcu" build/mcu-ctest.log ctest --test-dir build/default -L '^mcu$' \
      --output-on-failure; then
    r="FAILED (see build/mcu-ctest.log)"; status=1
  fi
  summary+=("mcu: $r ($(($(date +%s) - t0)) s)")
}

stage_package() {  # the Debian package of one build tree
  local c=$1 t0 r log
  echo "=== package of $c ==="
  t0=$(date +%s)
  log=build/$c/package.log
  # ctest exits 0 for a skipped test; the summary then says why from the test output.
  if ODO_PACKAGE_INSTALL=1 gated "package $c" "$log" ctest --test-dir "build/$c" -L package \
      --output-on-failure -V >/dev/null
  then r=ok; else r=FAILED; status=1; fi
  grep -E '^[0-9]+: (FAIL|SKIPPED|size|package|check_deb)' "$log" | cut -d' ' -f2- || true
  if grep -Eq '^[0-9]+: SKIPPED|check_deb .*SKIPPED' "$log"; then
    # A check skipped inside check_deb.sh (no root, no systemd-analyze...): not a pass in CI.
    if in_ci; then r="FAILED under CI (part skipped, see above)"; status=1; n_fail=$((n_fail + 1))
    else r="$r (part skipped, see above)"; fi
  fi
  summary+=("package $c: $r ($(($(date +%s) - t0)) s)")
  if [[ $c == default && ${ODO_FRESH_INSTALL:-1} == 1 ]]; then
    stage_fresh_install "$(ls -t build/default/diffodom_*_amd64.deb | head -1)"
  fi
}

# stage_rules: the house rules no compiler checks (tools/check_core.sh): the core rooms portable
# (no OS header, thread or stream; built with -fno-exceptions -fno-rtti) and no function over
# 60 lines, test targets named <tier>_<unit>. A broken rule fails the run like a failed test.
stage_rules() {
  local t0=$SECONDS
  if tools/check_core.sh portable composition functions tests 2>&1 | tee build/rules.log; then
    summary+=("rules: ok ($((SECONDS - t0)) s)")
    n_pass=$((n_pass + 1))
  else
    summary+=("rules: FAILED ($((SECONDS - t0)) s; build/rules.log)")
    failures+=("rules: $(grep -m1 '^check_core:' build/rules.log || echo 'see build/rules.log')")
    n_fail=$((n_fail + 1)) status=1
  fi
}

main() {
  cd "$ODO_ROOT"
  jobs=${ODO_JOBS:-$(nproc)}
  configs=${ODO_CONFIGS:-"default debug-asan tsan fuzz cross-aarch64 cross-armhf"}
  if [[ " $configs " == *" cross-"* ]]; then tools/setup.sh --tests --cross; else tools/setup.sh --tests; fi
  if in_ci; then echo "test.sh: CI=$CI: a skipped test or a stage that cannot run fails the run"; fi
  T_ALL=$(date +%s)
  if [[ ${ODO_KERNEL:-1} == 1 && " $configs " == *" default "* ]]; then vm_prepare_start; fi
  for c in $configs; do
    stage_config "$c"
    # The stages after default's and debug-asan's tiers leave CPU idle (the VM's one CPU, the
    # soak test): the sanitizer trees build beside them (about 8 min of CI's 66 at stop 36, on
    # one core until stop 40).
    # Only the sanitizer trees: their builds do not finish in the idle windows as it is (stop
    # 43's fresh-chroot run stopped both). Fuzz and the cross trees queued behind them were
    # resumed just before their own stage, which then built the same tree beside the builder.
    case $c in default) prebuild debug-asan tsan ;; *) prebuild_resume ;; esac
    if [[ $c == default ]]; then
      if [[ ${ODO_RULES:-1} == 1 ]]; then stage_rules; fi
      if [[ ${ODO_SOAK:-1} == 1 ]]; then stage_soak; fi
      # mcu before kernel: the kernel tier's kernel_mcu_slcan runs the image stage mcu builds.
      if [[ ${ODO_MCU:-1} == 1 ]]; then stage_mcu; fi  # needs the default tree's odometryd
      if [[ ${ODO_KERNEL:-1} == 1 ]]; then stage_kernel; fi
    fi
    # The ASan tree's kernel tier (the drivers' parsing of what the kernel hands them), but for
    # the 120 s drive of ResumeCanVcan.OneWheelStallingSender (the frame path of its short
    # neighbours, 122 s in the default tree) and
    # the three tests that SIGKILL a program over and over (100 kills during motion, the store's
    # writer killed at every point of a save): the same paths as their short neighbours, and
    # 5 of ASan's 7 min in the VM. From the tsan tree, the one driver with a thread of its own
    # (the GPIO decoder's event thread; the firmware's threads are in tsan's own tiers).
    if [[ ${ODO_KERNEL:-1} == 1 && $c == debug-asan ]]; then
      stage_kernel "$c" "kernel $c" --exclude-regex "SigkilledWriter|HundredSigkills|OneWheelStalling"
    elif [[ ${ODO_KERNEL:-1} == 1 && $c == tsan ]]; then
      stage_kernel "$c" "kernel $c" --tests-regex '^GpioQuadratureKernel\.'
    fi
  done
  if [[ ${ODO_PACKAGES:-1} == 1 ]]; then
    for c in $configs; do
      if [[ $c == default || $c == cross-* ]]; then stage_package "$c"; fi
    done
  fi
  echo "=== summary ($(($(date +%s) - T_ALL)) s in all) ==="
  printf '%s\n' "${summary[@]}"
  if ((${#failures[@]} > 0)); then echo "failed tests:"; printf '  %s\n' "${failures[@]}"; fi
  echo "all stages: $n_pass passed, $n_fail failed, $n_skip skipped"
  exit $status
}

if [[ ${BASH_SOURCE[0]} == "$0" ]]; then main "$@"; fi
