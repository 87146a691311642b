#!/usr/bin/env bash
# fresh_install.sh - install a diffodom .deb on a freshly bootstrapped Debian 12 (a chroot), the
# way a user installs it on a new machine: apt resolves Depends from the Debian mirror, so a
# missing or wrong dependency fails here even if the build machine happens to have the library.
#   tests/package/fresh_install.sh DEB [CHROOT_DIR]
# Needs root, debootstrap and the Debian mirror (deb.debian.org). The chroot (debootstrap
# --variant=minbase bookworm, about 2 minutes and 40 MB the first time) is kept in CHROOT_DIR
# (default /var/cache/diffodom-fresh-bookworm) and copied for each run, so every run starts clean.
# Runs the installed `odometryd --version`, `odomctl --help` and a 5 s simulated run with the
# installed config, then purges. The package's architecture must be the machine's.
# Exit 0 pass, 1 fail, 77 skipped (reason printed), 2 bad usage.
set -u
deb=${1:-}
base=${2:-/var/cache/diffodom-fresh-bookworm}
if [ -z "$deb" ] || [ ! -f "$deb" ]; then
  echo "usage: fresh_install.sh DEB [CHROOT_DIR]" >&2
  exit 2
fi
[ "$(id -u)" = 0 ] || { echo "SKIPPED: fresh install: needs root (debootstrap, chroot)"; exit 77; }
command -v debootstrap >/dev/null || { echo "SKIPPED: fresh install: debootstrap is not installed"; exit 77; }
arch=$(dpkg-deb -f "$deb" Architecture)
[ "$arch" = "$(dpkg --print-architecture)" ] ||
  { echo "SKIPPED: fresh install: $arch is not this machine's architecture"; exit 77; }

if [ ! -x "$base/bin/sh" ]; then
  echo "fresh install: debootstrap --variant=minbase bookworm $base"
  rm -rf "$base.tmp"
  if ! debootstrap --variant=minbase bookworm "$base.tmp" http://deb.debian.org/debian \
      >"$base.log" 2>&1; then
    tail -5 "$base.log"
    echo "SKIPPED: fresh install: debootstrap failed (no mirror?), see $base.log"
    exit 77
  fi
  mv "$base.tmp" "$base"
fi
root=$(mktemp -d /tmp/diffodom-fresh.XXXXXX)
cleanup() {
  umount "$root/proc" 2>/dev/null
  rm -rf "$root"
}
trap cleanup EXIT
cp -a "$base/." "$root/"
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
cp "$deb" "$root/tmp/"
name=$(basename "$deb")
fail=0
step() {  # step NAME COMMAND...   (run inside the chroot)
  if chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
      sh -c "$2" >"$root/tmp/step.log" 2>&1; then
    echo "ok:   $1"
  else
    fail=1; echo "FAIL: $1"; tail -20 "$root/tmp/step.log"
  fi
}
step "fresh chroot has no diffodom dependency yet" '! dpkg -s libtomlplusplus3 >/dev/null 2>&1'
step "apt-get update" 'apt-get update -qq'
step "apt-get install ./$name (Depends from the mirror)" \
  "apt-get install -y -qq --no-install-recommends /tmp/$name"
step "odometryd --version" "[ \"\$(/usr/bin/odometryd --version)\" = \"odometryd $(dpkg-deb -f "$deb" Version)\" ]"
step "odomctl --help" '/usr/bin/odomctl --help | grep -q replay'
step "odometryd runs the installed config (5 s virtual time)" \
  '/usr/bin/odometryd --config /etc/odometryd/odometryd.toml --virtual-time --duration 5 --quiet'
step "/var/lib/odometryd exists" '[ -d /var/lib/odometryd ]'
step "apt-get purge" 'apt-get purge -y -qq diffodom && [ ! -e /usr/bin/odometryd ] && [ ! -e /etc/odometryd ]'
echo "fresh install of $name: $([ $fail = 0 ] && echo passed || echo FAILED)"
exit $fail
