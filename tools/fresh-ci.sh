#!/usr/bin/env bash
# fresh-ci.sh - run the README's test command (CI=true bash .ci/run) as on a fresh machine: in a
# freshly bootstrapped Debian 12 chroot (minbase + git + ca-certificates: empty apt lists, no
# test packages, empty VM cache, no fresh-install chroot), on a clean clone of REPO.
#   tools/fresh-ci.sh [REPO] [CHROOT_DIR]     (root; needs debootstrap and Debian's mirror)
# Prints the debootstrap time; the run's output and wall time go to CHROOT_DIR.log.
# The chroot is made once and reused (delete it for a new fresh state: apt and VM caches live in
# it). Issue 14: TESTING.md records what such a run measured.
set -u
repo=${1:-$(cd "$(dirname "$0")/.." && pwd)}
R=${2:-/var/tmp/diffodom-fresh-ci}
[ "$(id -u)" = 0 ] || { echo "fresh-ci.sh: needs root" >&2; exit 2; }
t0=$(date +%s)
if [ ! -x "$R/bin/sh" ]; then
  debootstrap --variant=minbase --include=git,ca-certificates bookworm "$R" \
    http://deb.debian.org/debian >"$R.debootstrap.log" 2>&1 || { echo "debootstrap failed: $R.debootstrap.log"; exit 1; }
fi
# The host's apt sources (bookworm, -updates, -security), as a machine of the CI kind has them.
cp /etc/apt/sources.list.d/debian.sources "$R/etc/apt/sources.list.d/" && rm -f "$R/etc/apt/sources.list"
cp /etc/resolv.conf "$R/etc/resolv.conf"
# The CI kind's own certificate authorities (its network's TLS egress proxy signs with them):
# a fresh machine of the kind has them, a bare debootstrap does not (npm then fails with
# SELF_SIGNED_CERT_IN_CHAIN), so they are copied in and installed the way the kind has them.
if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
  mkdir -p "$R/usr/local/share/ca-certificates"
  cp /usr/local/share/ca-certificates/*.crt "$R/usr/local/share/ca-certificates/"
  chroot "$R" update-ca-certificates >/dev/null 2>&1 || { echo "fresh-ci: update-ca-certificates failed"; exit 1; }
fi
for m in proc sys dev dev/pts; do mountpoint -q "$R/$m" || mount --bind "/$m" "$R/$m"; done
echo "fresh-ci: chroot ready in $(($(date +%s) - t0)) s"
rm -rf "$R/root/repo" && git clone -q "$repo" "$R/root/repo"
t1=$(date +%s)
bundle=/etc/ssl/certs/ca-certificates.crt  # node and npm read the CAs from these, as on the kind
# In a mount namespace of its own with the chroot bound onto itself: its / is then a mount point,
# as a real machine's is, so that `unshare --mount` works inside (cli_golden_installed; in a bare
# chroot it fails: "cannot change root filesystem propagation").
unshare --mount sh -c 'mount --rbind "$1" "$1" && shift && exec "$@"' fresh "$R" \
  chroot "$R" /usr/bin/env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin CI=true LANG=C.UTF-8 \
  NODE_EXTRA_CA_CERTS=$bundle SSL_CERT_FILE=$bundle \
  bash -c 'cd /root/repo && bash .ci/run' >"$R.log" 2>&1
rc=$?
echo "fresh-ci: .ci/run exit $rc after $(($(date +%s) - t1)) s; output in $R.log" | tee -a "$R.log"
exit $rc
