#!/usr/bin/env bash
# odometryd's real-time set-up report, its behaviour without privilege (carry on, or refuse
# with `required = true`), --stats, and the systemd notify protocol end to end (READY=1,
# WATCHDOG=1 while the loop runs, STOPPING=1) over a real AF_UNIX datagram socket.
set -u
. "$(dirname "$0")/lib.sh"  # run, check, $tmp, jget
chmod 755 "$tmp"  # the unprivileged runs below must reach it

# Each part is reported at start; --stats prints the timing table at exit.
run "$ODOMETRYD" --duration 0.3 --quiet --stats >"$tmp/out" 2>"$tmp/err"
check "plain run exit 0 (got $?)" $?
for part in "SCHED_FIFO" "mlockall" "CPU affinity" "stack pre-fault" "CPU wake-up latency"; do
  grep -q "odometryd: realtime: $part" "$tmp/out"; check "part '$part' reported" $?
done
grep -Eq "wake-up latency +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+" "$tmp/out"
check "--stats wake-up latency row" $?
grep -Eq "compute time +[0-9.]+" "$tmp/out"; check "--stats compute time row" $?
grep -q "timing over [0-9]* ticks" "$tmp/out"; check "--stats header" $?

# Without privilege: no CAP_SYS_NICE / CAP_IPC_LOCK (dropped when root), RLIMIT_RTPRIO and
# RLIMIT_MEMLOCK 0. The daemon says so and carries on.
unpriv=(prlimit --rtprio=0:0 --memlock=0:0)
if [ "$(id -u)" = 0 ]; then
  unpriv=(setpriv --reuid=65534 --regid=65534 --clear-groups --inh-caps=-all --bounding-set=-all
    "${unpriv[@]}")
fi
# The unprivileged user must reach the binary: the build tree may sit below a directory only
# root can enter (a clone in /root, as on a fresh CI machine), so it runs a copy from $tmp.
cp "$ODOMETRYD" "$tmp/odometryd" && chmod 755 "$tmp/odometryd"
printf '[realtime]\npriority = 50\nlock_memory = true\ncpu_latency_us = 0\n' >"$tmp/rt.toml"
printf '[realtime]\npriority = 50\nlock_memory = true\nrequired = true\n' >"$tmp/rtreq.toml"
chmod 644 "$tmp"/*.toml
"${unpriv[@]}" ${CROSS_EMULATOR:-} "$tmp/odometryd" --config "$tmp/rt.toml" --duration 0.3 --quiet \
  >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 0 ]; check "unprivileged carries on: exit 0 (got $rc)" $?
grep -q "SCHED_FIFO priority 50: NOT APPLIED: not permitted.*CAP_SYS_NICE.*; continuing" "$tmp/out"
check "unprivileged: SCHED_FIFO not permitted, said clearly" $?
grep -Eq "mlockall: NOT APPLIED: (not permitted.*CAP_IPC_LOCK|.*(Address|Thread)Sanitizer).*; continuing" \
  "$tmp/out"
check "unprivileged: mlockall not permitted, said clearly" $?
grep -q "CPU wake-up latency (PM QoS) 0 us: NOT APPLIED: /dev/cpu_dma_latency: EACCES.*; continuing" \
  "$tmp/out"
check "unprivileged: the PM QoS request not permitted, said clearly" $?
grep -q "odometryd: stopped after" "$tmp/out"; check "unprivileged: the loop ran" $?
"${unpriv[@]}" ${CROSS_EMULATOR:-} "$tmp/odometryd" --config "$tmp/rtreq.toml" --duration 0.3 --quiet \
  >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 1 ]; check "required = true refuses: exit 1 (got $rc)" $?
grep -q "required = true: refusing to start" "$tmp/err"; check "refusal reason on stderr" $?
! grep -q "odometryd: stopped after" "$tmp/out"; check "refused: the loop never ran" $?

# A bad [realtime] value: exit 2, file, line and field named.
printf '[realtime]\ncpu = -2\n' >"$tmp/bad.toml"
run "$ODOMETRYD" --config "$tmp/bad.toml" --duration 0.1 >"$tmp/out" 2>"$tmp/err"
rc=$?; [ $rc = 2 ]; check "bad cpu exit 2 (got $rc)" $?
grep -q "bad.toml:2.*cpu" "$tmp/err"; check "bad cpu: line and field named" $?

# systemd notify protocol against a real datagram socket, as systemd would set it up.
python3 - "$ODOMETRYD" "$tmp/notify.sock" "${CROSS_EMULATOR:-}" <<'PY'
import os, re, socket, subprocess, sys
exe, path = sys.argv[1], sys.argv[2]
# A cross build's binary runs under its emulator (qemu-user), as run() does above.
emulator = [a for a in re.split(r"[ ;]", sys.argv[3]) if a]
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(path)
env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC="200000")
# Read while the daemon runs, as systemd does (the queue of a datagram socket is short).
p = subprocess.Popen(emulator + [exe, "--duration", "1.5", "--quiet"], env=env, stdout=subprocess.PIPE,
                     stderr=subprocess.PIPE, text=True)
s.settimeout(0.2)
msgs = []
while True:
    try:
        msgs.append(s.recv(256).decode())
    except socket.timeout:
        if p.poll() is not None:
            break
out, err = p.communicate(timeout=10)
assert p.returncode == 0, err
assert "systemd notify: on, watchdog 0.2" in out, out
assert msgs and msgs[0].startswith("READY=1"), msgs
pings = sum(m.startswith("WATCHDOG=1") for m in msgs)
# 1.5 s of loop, a ping every 0.1 s: about 14; every one needs the tick counter to advance.
assert 10 <= pings <= 16, (pings, msgs)
assert msgs[-1] == "STOPPING=1", msgs
assert not any("stalled" in m for m in msgs), msgs
PY
check "sd_notify READY/WATCHDOG/STOPPING" $?

echo "test_realtime.sh: $pass passed, $fail failed"
[ $fail = 0 ]
