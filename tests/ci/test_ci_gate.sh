#!/usr/bin/env bash
# test_ci_gate.sh - tools/test.sh's CI gate (issue 14): under CI=true a kernel stage whose VM
# cannot start, a stage in which a test reports skipped, and a stage that ran no test each fail
# the run with the reason, and the closing line counts the skips as failures; outside CI the same
# runs pass with the skips counted as skipped. The VM is made unavailable for real (the harness is
# asked for a kernel package that does not exist, in an empty cache); the "VM starts but a test
# skips" case uses a stand-in harness that runs a tiny ctest project on the host.
#   test_ci_gate.sh REPO_ROOT
set -u
root=${1:?usage: test_ci_gate.sh REPO_ROOT}
pass=0 fail=0
check() { if [ "$2" = 0 ]; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $1"; fi; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

# A ctest tree with one passing and one skipping kernel-tier test, where test.sh looks for it.
mkdir -p "$tmp/w/build/default"
cat >"$tmp/w/build/default/CTestTestfile.cmake" <<'CT'
add_test(k_pass "/bin/true")
set_tests_properties(k_pass PROPERTIES LABELS kernel)
add_test(k_skip "/bin/sh" "-c" "echo 'SKIPPED: no vcan in this kernel'; exit 77")
set_tests_properties(k_skip PROPERTIES LABELS kernel SKIP_RETURN_CODE 77)
CT
# Stand-in harness: "prepares" and runs the command on the host (as the VM would, minus the VM).
cat >"$tmp/fake-vm-run.sh" <<'SH'
#!/usr/bin/env bash
[ "$1" = --prepare ] && exit 0
while [ "$1" != -- ]; do shift; done; shift
exec "$@"
SH
chmod +x "$tmp/fake-vm-run.sh"

# stage CI_VALUE VM_RUN [ENV...] -- runs test.sh's kernel stage in a subshell, prints its
# summary line, the closing line and "status=N".
stage() {
  local ci=$1 vm=$2; shift 2
  (cd "$tmp/w" && env "$@" CI="$ci" ODO_VM_RUN="$vm" bash -c '
    . "$0"/tools/test.sh
    stage_kernel >"$1"/stage.out 2>&1
    printf "%s\n" "${summary[@]}"
    echo "all stages: $n_pass passed, $n_fail failed, $n_skip skipped"
    echo "status=$status"' "$root" "$tmp")
}

# 1. Under CI, the VM cannot start (no such kernel package, empty cache): red, with the reason.
if [ "$(id -u)" = 0 ]; then
  out=$(stage true "$root/tools/vm-run.sh" VMRUN_QUIET=1 VMRUN_CACHE="$tmp/cache" \
    VMRUN_KPKG=linux-image-0.0.0-0-nonexistent)
  echo "$out"
  check "CI, no VM: status 1" "$(echo "$out" | grep -qx 'status=1'; echo $?)"
  check "CI, no VM: the summary names the reason" \
    "$(echo "$out" | grep -q 'kernel: FAILED (VM harness unavailable: vm-run: package linux-image-0.0.0-0-nonexistent not found'; echo $?)"
  check "CI, no VM: no test counted as skipped" "$(echo "$out" | grep -q ', 0 skipped$'; echo $?)"
  # 2. Outside CI the same machine skips loudly and stays green.
  out=$(stage "" "$root/tools/vm-run.sh" VMRUN_QUIET=1 VMRUN_CACHE="$tmp/cache" \
    VMRUN_KPKG=linux-image-0.0.0-0-nonexistent)
  echo "$out"
  check "no CI, no VM: skipped, status 0" \
    "$(echo "$out" | grep -q 'kernel: skipped (no VM)' && echo "$out" | grep -qx 'status=0'; echo $?)"
  check "no CI, no VM: said loudly" "$(grep -q 'VM harness is unavailable' "$tmp/stage.out"; echo $?)"
else
  echo "cases 1-2 need root (tools/vm-run.sh does); CI runs as root"
  check "running as root (tools/vm-run.sh needs it)" 1
fi

# 3. Under CI, the VM starts but a kernel test reports skipped: red, the skip counted as failed.
out=$(stage true "$tmp/fake-vm-run.sh")
echo "$out"
check "CI, test skipped: status 1" "$(echo "$out" | grep -qx 'status=1'; echo $?)"
check "CI, test skipped: stage FAILED" "$(echo "$out" | grep -q '^kernel: FAILED'; echo $?)"
check "CI, test skipped: closing line 1 passed, 1 failed, 0 skipped" \
  "$(echo "$out" | grep -qx 'all stages: 1 passed, 1 failed, 0 skipped'; echo $?)"
check "CI, test skipped: the reason is printed" \
  "$(grep -q 'kernel: FAILED under CI: 1 test(s) reported skipped' "$tmp/stage.out"; echo $?)"
# 4. Outside CI the same run is green with one skip.
out=$(stage "" "$tmp/fake-vm-run.sh")
check "no CI, test skipped: ok, 1 passed, 0 failed, 1 skipped" \
  "$(echo "$out" | grep -q '^kernel: ok' && echo "$out" | grep -qx 'all stages: 1 passed, 0 failed, 1 skipped'; echo $?)"
# 5. A failing test is named in the summary, with its GoogleTest failure report or a script's
# failed check: CI shows only the tail of the run.
cat >"$tmp/w/build/default/CTestTestfile.cmake" <<'CT'
add_test(k_pass "/bin/true")
set_tests_properties(k_pass PROPERTIES LABELS kernel)
add_test(k_fail "/bin/sh" "-c" "printf 'x.cpp:7: Failure\\nExpected: gap < 1.5\\n'; exit 1")
set_tests_properties(k_fail PROPERTIES LABELS kernel)
add_test(k_script "/bin/sh" "-c" "echo 'FAIL: pane shows the prompt'; exit 1")
set_tests_properties(k_script PROPERTIES LABELS kernel)
CT
out=$(cd "$tmp/w" && CI=true ODO_VM_RUN="$tmp/fake-vm-run.sh" bash -c '
  . "$0"/tools/test.sh
  stage_kernel >/dev/null 2>&1
  printf "%s\n" "${failures[@]}"' "$root")
echo "$out"
check "failed test named with its log" \
  "$(echo "$out" | grep -qE '^build/default/kernel.log: 2 - k_fail \(Failed\)$'; echo $?)"
check "its failure report follows" "$(echo "$out" | grep -q 'Expected: gap < 1.5'; echo $?)"
check "a script test's failed check follows" \
  "$(echo "$out" | grep -q 'FAIL: pane shows the prompt'; echo $?)"

# 6. Under CI, a stage that ran no test at all fails.
rm "$tmp/w/build/default/CTestTestfile.cmake"
: >"$tmp/w/build/default/CTestTestfile.cmake"
out=$(stage true "$tmp/fake-vm-run.sh")
check "CI, no test ran: status 1" "$(echo "$out" | grep -qx 'status=1'; echo $?)"
check "CI, no test ran: the reason is printed" \
  "$(grep -q 'kernel: FAILED under CI: no test ran' "$tmp/stage.out"; echo $?)"

# 7. A sanitizer tree's kernel tier: a report written by a program a test started (its test
# passed: the program was killed, or its stderr went nowhere) fails the stage; the tests the
# stage excludes do not run.
mkdir -p "$tmp/w/build/debug-asan"
cat >"$tmp/w/build/debug-asan/CTestTestfile.cmake" <<'CT'
add_test(k_pass "/bin/true")
set_tests_properties(k_pass PROPERTIES LABELS kernel)
add_test(k_child "/bin/sh" "-c" "echo 'ERROR: AddressSanitizer: heap-use-after-free' >\"\${ASAN_OPTIONS#log_path=}.4242\"")
set_tests_properties(k_child PROPERTIES LABELS kernel)
add_test(k_repeated_kills "/bin/false")
set_tests_properties(k_repeated_kills PROPERTIES LABELS kernel)
CT
out=$(cd "$tmp/w" && CI=true ODO_VM_RUN="$tmp/fake-vm-run.sh" bash -c '
  . "$0"/tools/test.sh
  stage_kernel debug-asan "kernel debug-asan" --exclude-regex repeated_kills >"$1"/stage.out 2>&1
  printf "%s\n" "${summary[@]}" "${failures[@]}"
  echo "all stages: $n_pass passed, $n_fail failed, $n_skip skipped"
  echo "status=$status"' "$root" "$tmp")
echo "$out"
check "sanitizer report: status 1" "$(echo "$out" | grep -qx 'status=1'; echo $?)"
check "sanitizer report: stage FAILED, named" \
  "$(echo "$out" | grep -q '^kernel debug-asan: FAILED' && echo "$out" | grep -q 'kernel debug-asan: sanitizer reports in'; echo $?)"
check "sanitizer report: printed" "$(grep -q 'heap-use-after-free' "$tmp/stage.out"; echo $?)"
check "sanitizer report: the excluded test did not run (2 passed, 1 failed)" \
  "$(echo "$out" | grep -qx 'all stages: 2 passed, 1 failed, 0 skipped'; echo $?)"

echo "ci gate: $pass passed, $fail failed"
[ "$fail" = 0 ]
