#!/usr/bin/env bash
# check_deb.sh - build the Debian package of one build tree with CPack and check it.
#   check_deb.sh BUILD_DIR SOURCE_DIR DEB_ARCH [--install]
# Checks, for any architecture: the control fields (Package, Architecture), the files the package
# must hold (binaries, conffile, store directory, DBC and systemd unit once they exist in the
# source tree), the ELF machine of both binaries (readelf: AArch64 / ARM hard-float / X86-64), that
# they are stripped, and that Depends names the package of every shared library the binaries need
# (DT_NEEDED resolved in the target's multiarch directories, owner from dpkg -S).
# With --install and ODO_PACKAGE_INSTALL=1 in the environment (only for the machine's own
# architecture, as root; tools/test.sh sets it: CI is a throw-away machine):
# dpkg -i, run `odometryd --version`, `odomctl --help` and a short simulated run from the installed
# paths with the installed config, `systemd-analyze verify` the installed unit, then remove and
# purge and check what stays (the conffile after remove, a non-empty calibration store after purge).
# Exit 0: all checks passed; 1: a check failed; 77: the install part was asked for but cannot run
# here (reason printed); 2: bad usage.
set -u
if [ $# -lt 3 ]; then
  echo "usage: check_deb.sh BUILD_DIR SOURCE_DIR DEB_ARCH [--install]" >&2
  exit 2
fi
build=$1 src=$2 arch=$3 install=${4:-}
fail=0 pass=0 skip_reason=""
ok() { pass=$((pass + 1)); echo "ok:   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL: $1"; }
check() { if eval "$2"; then ok "$1"; else bad "$1"; fi; }

case $arch in
  amd64) triple=x86_64-linux-gnu machine="Advanced Micro Devices X86-64" ;;
  arm64) triple=aarch64-linux-gnu machine="AArch64" ;;
  armhf) triple=arm-linux-gnueabihf machine="ARM" ;;
  *) echo "check_deb.sh: unknown Debian architecture '$arch' (amd64, arm64, armhf)" >&2; exit 2 ;;
esac

# 1. Build the package (cpack installs what the build tree has built; it does not rebuild).
(cd "$build" && cpack -G DEB >cpack.log 2>&1) || { cat "$build/cpack.log"; echo "FAIL: cpack"; exit 1; }
deb=$(ls -t "$build"/diffodom_*_"$arch".deb 2>/dev/null | head -1)
[ -n "$deb" ] || { echo "FAIL: no diffodom_*_$arch.deb in $build"; exit 1; }
echo "package: $deb ($(stat -c %s "$deb") bytes)"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

# 2. Control fields and contents.
check "Package: diffodom" '[ "$(dpkg-deb -f "$deb" Package)" = diffodom ]'
check "Architecture: $arch" '[ "$(dpkg-deb -f "$deb" Architecture)" = "$arch" ]'
dpkg-deb -c "$deb" | awk '{print $6}' | sed 's|^\./|/|; s|/$||' >"$tmp/files"
want=(/usr/bin/odometryd /usr/bin/odomctl /etc/odometryd/odometryd.toml /var/lib/odometryd)
if [ -f "$src/protocol/odometry.dbc" ]; then
  want+=(/usr/share/odometryd/odometry.dbc)
else
  echo "note: protocol/odometry.dbc is not in the source tree yet; not expected in the package"
fi
if [ -f "$src/firmware/systemd/odometryd.service" ]; then
  want+=(/lib/systemd/system/odometryd.service)
else
  echo "note: firmware/systemd/odometryd.service is not in the source tree yet; not expected"
fi
for f in "${want[@]}"; do check "contains $f" 'grep -qx "$f" "$tmp/files"'; done
dpkg-deb -e "$deb" "$tmp/control"
check "conffiles lists /etc/odometryd/odometryd.toml" \
  'grep -qx /etc/odometryd/odometryd.toml "$tmp/control/conffiles"'
dpkg-deb -x "$deb" "$tmp/root"
check "shipped config is firmware/config/odometryd.toml" \
  'cmp -s "$tmp/root/etc/odometryd/odometryd.toml" "$src/firmware/config/odometryd.toml"'
check "/var/lib/odometryd is a directory" '[ -d "$tmp/root/var/lib/odometryd" ]'

# 3. The binaries: machine, float ABI, stripped, and what they need at run time.
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
# Package names in Depends (alternatives a | b count as named), one per line.
echo "$depends" | tr ',|' '\n\n' | sed 's/^ *//; s/[ (].*//' >"$tmp/depends"
for b in odometryd odomctl; do
  f=$tmp/root/usr/bin/$b
  check "$b: ELF machine $machine" \
    '[ "$(readelf -h "$f" | sed -n "s/^ *Machine: *//p")" = "$machine" ]'
  if [ "$arch" = armhf ]; then
    check "$b: hard-float ABI" 'readelf -h "$f" | grep -q "hard-float ABI"'
    check "$b: ARMv7 (Debian armhf baseline)" 'readelf -A "$f" | grep -q "Tag_CPU_arch: v7"'
  fi
  check "$b: stripped (no .symtab)" '! readelf -S "$f" | grep -q "\.symtab"'
  echo "size: $arch $b $(stat -c %s "$f") bytes stripped; file: $(file -b "$f" | cut -c1-90)"
  for lib in $(readelf -d "$f" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    path=""
    for d in /lib/$triple /usr/lib/$triple; do
      if [ -e "$d/$lib" ]; then path=$d/$lib; break; fi
    done
    if [ -z "$path" ]; then bad "$b: $lib not found in /lib/$triple or /usr/lib/$triple"; continue; fi
    owner=$(dpkg -S "$path" 2>/dev/null | head -1 | cut -d: -f1)
    [ -n "$owner" ] || owner=$(dpkg -S "$(readlink -f "$path")" 2>/dev/null | head -1 | cut -d: -f1)
    check "$b: needs $lib ($owner:$arch), Depends names $owner" \
      '[ -n "$owner" ] && grep -qxF "$owner" "$tmp/depends"'
  done
done

# 4. Install, run, verify the unit, remove and purge (host architecture only).
if [ "$install" = --install ]; then
  if [ "${ODO_PACKAGE_INSTALL:-0}" != 1 ]; then
    skip_reason="install test: it installs and purges the package on this machine; set ODO_PACKAGE_INSTALL=1 to allow it"
  elif [ "$arch" != "$(dpkg --print-architecture)" ]; then
    skip_reason="install test: $arch is not this machine's architecture"
  elif [ "$(id -u)" != 0 ]; then
    skip_reason="install test: needs root (dpkg -i)"
  elif dpkg-query -W -f='${Status}' diffodom 2>/dev/null | grep -q installed; then
    skip_reason="install test: a diffodom package is already installed here; not touching it"
  else
    echo "--- dpkg -i $deb"
    check "dpkg -i" 'dpkg -i "$deb" >"$tmp/dpkg.log" 2>&1 || { cat "$tmp/dpkg.log"; false; }'
    check "dpkg status: install ok installed" \
      '[ "$(dpkg-query -W -f="\${Status}" diffodom)" = "install ok installed" ]'
    check "odometryd --version from /usr/bin" \
      '[ "$(/usr/bin/odometryd --version)" = "odometryd $(dpkg-deb -f "$deb" Version)" ]'
    check "odomctl --help from /usr/bin" \
      '/usr/bin/odomctl --help >"$tmp/help" 2>&1 && grep -q replay "$tmp/help"'
    check "installed binaries find all their libraries" \
      '! ldd /usr/bin/odometryd /usr/bin/odomctl | grep -q "not found"'
    check "installed odometryd runs the installed config (5 s virtual time)" \
      '/usr/bin/odometryd --config /etc/odometryd/odometryd.toml --virtual-time --duration 5 --json --quiet >"$tmp/run.json" && python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j[\"ticks\"] >= 499, j" "$tmp/run.json"'
    check "/var/lib/odometryd exists after install" '[ -d /var/lib/odometryd ]'
    unit=/lib/systemd/system/odometryd.service
    user=$(sed -n 's/^[[:space:]]*User=[[:space:]]*//p' "$unit" 2>/dev/null | tail -n 1)
    if [ -n "$user" ] && [ "$user" != root ]; then
      check "the unit's User=$user exists and owns /var/lib/odometryd" \
        'getent passwd "$user" >/dev/null && [ "$(stat -c %U /var/lib/odometryd)" = "$user" ]'
    fi
    if [ -f "$unit" ]; then
      if command -v systemd-analyze >/dev/null; then
        check "systemd-analyze verify $unit" \
          'systemd-analyze verify --man=no "$unit" >"$tmp/verify" 2>&1 || { cat "$tmp/verify"; false; }'
        [ -s "$tmp/verify" ] && { echo "systemd-analyze verify said:"; cat "$tmp/verify"; }
      else
        echo "SKIPPED: systemd-analyze verify: systemd-analyze is not installed"
      fi
    else
      echo "SKIPPED: systemd-analyze verify: the package has no unit yet (firmware/systemd/odometryd.service is not in the source tree)"
    fi
    # A store that holds a record survives remove and purge (postrm); an empty directory does not.
    [ -e /var/lib/odometryd/calibration.bin ] && keep_store=1 || keep_store=0
    [ $keep_store = 1 ] || echo "test record" >/var/lib/odometryd/calibration.bin
    echo "--- dpkg -r diffodom"
    check "dpkg -r" 'dpkg -r diffodom >"$tmp/dpkg.log" 2>&1 || { cat "$tmp/dpkg.log"; false; }'
    check "binaries gone after remove" '[ ! -e /usr/bin/odometryd ] && [ ! -e /usr/bin/odomctl ]'
    check "conffile kept after remove" '[ -f /etc/odometryd/odometryd.toml ]'
    check "calibration store kept after remove" '[ -f /var/lib/odometryd/calibration.bin ]'
    echo "--- dpkg -P diffodom"
    check "dpkg -P" 'dpkg -P diffodom >"$tmp/dpkg.log" 2>&1 || { cat "$tmp/dpkg.log"; false; }'
    check "config gone after purge" '[ ! -e /etc/odometryd/odometryd.toml ]'
    check "non-empty calibration store kept after purge" '[ -f /var/lib/odometryd/calibration.bin ]'
    if [ $keep_store = 0 ]; then
      rm -f /var/lib/odometryd/calibration.bin
      rmdir /var/lib/odometryd 2>/dev/null
    fi
    check "nothing of the package left in dpkg" '! dpkg-query -W diffodom >/dev/null 2>&1'
  fi
fi

echo "check_deb $arch: $pass passed, $fail failed${skip_reason:+, SKIPPED: $skip_reason}"
[ $fail = 0 ] || exit 1
[ -z "$skip_reason" ] || exit 77
exit 0
